#include "rigger/sim/trapezoid_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::sim {
namespace {

// Samples the profile finely and checks every dimension's speed and acceleration against its
// limits, and that s runs monotonically from 0 to 1.
void expect_within_limits(const TrapezoidProfile& profile, const Eigen::VectorXd& distances,
                          const Eigen::VectorXd& speeds, const Eigen::VectorXd& accels) {
  const double dt = profile.duration_s() / 2000.0;
  double previous_s = 0.0;
  for (int i = 0; i <= 2000; ++i) {
    const TrapezoidProfile::Sample sample = profile.sample(i * dt);
    EXPECT_GE(sample.s, previous_s - 1e-12);
    previous_s = sample.s;
    for (Eigen::Index d = 0; d < distances.size(); ++d) {
      EXPECT_LE(distances[d] * sample.ds, speeds[d] * (1 + 1e-9));
      EXPECT_LE(distances[d] * std::abs(sample.dds), accels[d] * (1 + 1e-9));
    }
  }
  EXPECT_DOUBLE_EQ(profile.sample(profile.duration_s()).s, 1.0);
  EXPECT_DOUBLE_EQ(profile.sample(-1.0).s, 0.0);
  EXPECT_DOUBLE_EQ(profile.sample(profile.duration_s() + 1.0).ds, 0.0);
}

TEST(TrapezoidProfile, LongMoveCruisesAtTheBindingSpeedLimit) {
  const Eigen::VectorXd distances = Eigen::Vector3d(2.0, 0.5, 1.0);
  const Eigen::VectorXd speeds = Eigen::Vector3d(1.0, 1.0, 0.25);
  const Eigen::VectorXd accels = Eigen::Vector3d(2.0, 2.0, 2.0);
  const auto profile = TrapezoidProfile::plan(distances, speeds, accels);
  ASSERT_TRUE(profile.has_value());
  // Dimension 2 binds speed (1.0 m at 0.25 m/s: 4 s cruise-equivalent), dimension 0 binds
  // acceleration (2.0 m / 2 m/s^2 = 1 s^2): T = V + A / V = 4 + 0.25.
  EXPECT_NEAR(profile->duration_s(), 4.25, 1e-12);
  const TrapezoidProfile::Sample middle = profile->sample(2.0);
  EXPECT_NEAR(distances[2] * middle.ds, 0.25, 1e-12);
  expect_within_limits(*profile, distances, speeds, accels);
}

TEST(TrapezoidProfile, ShortMoveIsTriangular) {
  const Eigen::VectorXd distances = Eigen::Vector2d(0.01, 0.0);
  const Eigen::VectorXd speeds = Eigen::Vector2d(1.0, 1.0);
  const Eigen::VectorXd accels = Eigen::Vector2d(1.0, 1.0);
  const auto profile = TrapezoidProfile::plan(distances, speeds, accels);
  ASSERT_TRUE(profile.has_value());
  EXPECT_NEAR(profile->duration_s(), 2.0 * std::sqrt(0.01), 1e-12);
  const TrapezoidProfile::Sample peak = profile->sample(profile->duration_s() / 2);
  EXPECT_NEAR(distances[0] * peak.ds, std::sqrt(0.01), 1e-9);  // below the 1 m/s limit
  expect_within_limits(*profile, distances, speeds, accels);
}

TEST(TrapezoidProfile, NothingToDoTakesNoTime) {
  const auto profile = TrapezoidProfile::plan(Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones(),
                                              Eigen::Vector2d::Ones());
  ASSERT_TRUE(profile.has_value());
  EXPECT_DOUBLE_EQ(profile->duration_s(), 0.0);
  EXPECT_DOUBLE_EQ(profile->sample(0.0).s, 1.0);
}

TEST(TrapezoidProfile, RejectsBadInput) {
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  EXPECT_FALSE(TrapezoidProfile::plan(Eigen::Vector2d::Ones(), one, one).has_value());
  EXPECT_FALSE(TrapezoidProfile::plan(-one, one, one).has_value());
  EXPECT_FALSE(TrapezoidProfile::plan(one, Eigen::VectorXd::Zero(1), one).has_value());
  EXPECT_FALSE(TrapezoidProfile::plan(one, one, -one).has_value());
  EXPECT_FALSE(
      TrapezoidProfile::plan(Eigen::VectorXd::Constant(1, std::nan("")), one, one).has_value());
  EXPECT_FALSE(
      TrapezoidProfile::plan(one, Eigen::VectorXd::Constant(1, INFINITY), one).has_value());
}

}  // namespace
}  // namespace rigger::sim
