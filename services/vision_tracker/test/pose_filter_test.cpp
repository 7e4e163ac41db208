#include "pose_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rigger::vision {
namespace {

using std::chrono::milliseconds;

constexpr double kDeg = M_PI / 180.0;
const Stamp kT0 = Stamp(std::chrono::seconds(1000));

Eigen::Isometry3d pose_at(const Eigen::Vector3d& position, double yaw_rad) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = position;
  return p;
}

TEST(PoseFilter, FirstMeasurementIsTakenAsIs) {
  PoseFilter filter{FilterSettings{}};
  EXPECT_FALSE(filter.initialised());
  const Eigen::Isometry3d measured = pose_at({1, 2, 3}, 0.3);
  EXPECT_EQ(filter.update(measured, kT0), FilterUpdate::kRestarted);
  EXPECT_TRUE(filter.initialised());
  EXPECT_TRUE(filter.pose().isApprox(measured));
  EXPECT_EQ(filter.stamp(), kT0);
}

TEST(PoseFilter, SmoothsNoiseOnAStaticObject) {
  PoseFilter filter{FilterSettings{}};
  std::mt19937 rng(5);
  std::normal_distribution<double> noise_m(0.0, 0.001);
  std::normal_distribution<double> noise_rad(0.0, 0.2 * kDeg);
  const Eigen::Vector3d truth(0.5, 1.0, 1.2);
  double raw_sq = 0.0;
  double filtered_sq = 0.0;
  double raw_rot_sq = 0.0;
  double filtered_rot_sq = 0.0;
  int n = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Isometry3d measured =
        pose_at(truth + Eigen::Vector3d(noise_m(rng), noise_m(rng), noise_m(rng)), noise_rad(rng));
    filter.update(measured, kT0 + milliseconds(33 * i));
    if (i >= 30) {
      raw_sq += (measured.translation() - truth).squaredNorm();
      filtered_sq += (filter.pose().translation() - truth).squaredNorm();
      raw_rot_sq += std::pow(Eigen::AngleAxisd(measured.linear()).angle(), 2);
      filtered_rot_sq += std::pow(Eigen::AngleAxisd(filter.pose().linear()).angle(), 2);
      ++n;
    }
  }
  // Theory for the default gains: about 0.6 of the raw variance.
  EXPECT_LT(filtered_sq, 0.8 * raw_sq);
  EXPECT_LT(filtered_rot_sq, 0.8 * raw_rot_sq);
}

TEST(PoseFilter, FollowsConstantVelocityWithoutLagAtTheMeasurementStamp) {
  PoseFilter filter{FilterSettings{}};
  const Eigen::Vector3d velocity(0.2, -0.1, 0.05);  // m/s
  const double yaw_rate = 10.0 * kDeg;              // rad/s
  for (int i = 0; i <= 90; ++i) {
    const double t = 0.033 * i;
    filter.update(pose_at(velocity * t, yaw_rate * t), kT0 + milliseconds(33 * i));
  }
  // The pose is the object's at the last measurement's stamp (no extrapolation, no lag).
  const double t_end = 0.033 * 90;
  EXPECT_LT((filter.pose().translation() - velocity * t_end).norm(), 1e-4);
  EXPECT_NEAR(Eigen::AngleAxisd(filter.pose().linear()).angle(), yaw_rate * t_end, 1e-4);
  EXPECT_LT((filter.linear_velocity() - velocity).norm(), 1e-3);
  EXPECT_NEAR(filter.angular_velocity().z(), yaw_rate, 1e-3);
  EXPECT_EQ(filter.stamp(), kT0 + milliseconds(33 * 90));
}

TEST(PoseFilter, RestartsAfterAGapLongerThanMaxPrediction) {
  FilterSettings settings;
  settings.max_prediction = milliseconds(200);
  PoseFilter filter(settings);
  for (int i = 0; i < 10; ++i) {
    filter.update(pose_at(Eigen::Vector3d(0.01 * i, 0, 0), 0.0), kT0 + milliseconds(33 * i));
  }
  ASSERT_GT(filter.linear_velocity().x(), 0.1);
  // 250 ms later: predicting that far is not trusted; the measurement is taken as is.
  const Eigen::Isometry3d later = pose_at({0.0, 0.5, 0.0}, 0.0);
  EXPECT_EQ(filter.update(later, kT0 + milliseconds(33 * 9 + 250)), FilterUpdate::kRestarted);
  EXPECT_TRUE(filter.pose().isApprox(later));
  EXPECT_TRUE(filter.linear_velocity().isZero());
}

TEST(PoseFilter, RestartsOnAJumpBeyondTheResetThresholds) {
  PoseFilter filter{FilterSettings{}};
  filter.update(pose_at({0, 0, 0}, 0.0), kT0);
  filter.update(pose_at({0, 0, 0}, 0.0), kT0 + milliseconds(33));
  EXPECT_EQ(filter.update(pose_at({0.2, 0, 0}, 0.0), kT0 + milliseconds(66)), FilterUpdate::kRestarted);
  EXPECT_NEAR(filter.pose().translation().x(), 0.2, 1e-12);
  EXPECT_EQ(filter.update(pose_at({0.2, 0, 0}, 30.0 * kDeg), kT0 + milliseconds(99)), FilterUpdate::kRestarted);
  EXPECT_NEAR(Eigen::AngleAxisd(filter.pose().linear()).angle(), 30.0 * kDeg, 1e-9);
  EXPECT_EQ(filter.update(pose_at({0.201, 0, 0}, 30.0 * kDeg), kT0 + milliseconds(132)), FilterUpdate::kFiltered);
}

TEST(PoseFilter, RejectsOldStampsAndNonFinitePoses) {
  PoseFilter filter{FilterSettings{}};
  filter.update(pose_at({1, 0, 0}, 0.0), kT0);
  EXPECT_EQ(filter.update(pose_at({2, 0, 0}, 0.0), kT0), FilterUpdate::kRejected);
  EXPECT_EQ(filter.update(pose_at({2, 0, 0}, 0.0), kT0 - milliseconds(1)), FilterUpdate::kRejected);
  Eigen::Isometry3d bad = pose_at({1, 0, 0}, 0.0);
  bad.translation().y() = std::nan("");
  EXPECT_EQ(filter.update(bad, kT0 + milliseconds(10)), FilterUpdate::kRejected);
  EXPECT_TRUE(filter.pose().isApprox(pose_at({1, 0, 0}, 0.0)));
  EXPECT_EQ(filter.stamp(), kT0);
}

TEST(PoseFilter, DisabledPassesMeasurementsThrough) {
  FilterSettings settings;
  settings.enabled = false;
  PoseFilter filter(settings);
  filter.update(pose_at({0, 0, 0}, 0.0), kT0);
  const Eigen::Isometry3d next = pose_at({0.001, 0, 0}, 0.01);
  filter.update(next, kT0 + milliseconds(33));
  EXPECT_TRUE(filter.pose().isApprox(next));
}

TEST(PoseFilter, ResetForgets) {
  PoseFilter filter{FilterSettings{}};
  filter.update(pose_at({0, 0, 0}, 0.0), kT0);
  filter.reset();
  EXPECT_FALSE(filter.initialised());
  EXPECT_EQ(filter.update(pose_at({0, 0, 0}, 0.0), kT0 - milliseconds(5)), FilterUpdate::kRestarted);
}

TEST(RotationMaps, LogInvertsExp) {
  const Eigen::Vector3d v(0.3, -0.2, 0.5);
  EXPECT_TRUE(log_rotation(exp_rotation(v)).isApprox(v, 1e-12));
  EXPECT_TRUE(exp_rotation(Eigen::Vector3d::Zero()).isApprox(Eigen::Matrix3d::Identity()));
}

}  // namespace
}  // namespace rigger::vision
