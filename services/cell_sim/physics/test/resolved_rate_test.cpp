#include "rigger/sim/resolved_rate.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::sim {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Six joints each moving one twist component, a seventh duplicating the first: redundant along x.
Eigen::MatrixXd redundant_jacobian() {
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(6, 7);
  jacobian.leftCols<6>().setIdentity();
  jacobian(0, 6) = 1.0;
  return jacobian;
}

ResolvedRateLimits wide_limits(Eigen::Index n = 7) {
  ResolvedRateLimits limits;
  limits.position_min_rad = Eigen::VectorXd::Constant(n, -3.0);
  limits.position_max_rad = Eigen::VectorXd::Constant(n, 3.0);
  limits.speed_max_rad_per_s = Eigen::VectorXd::Constant(n, 1.0);
  limits.accel_max_rad_per_s2 = Eigen::VectorXd::Constant(n, 5.0);
  return limits;
}

ResolvedRateParams no_avoidance() {
  ResolvedRateParams params;
  params.limit_avoidance_gain = 0.0;
  return params;
}

TEST(ResolvedRate, RealisesAFeasibleTwistExactly) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Vector6d twist;
  twist << 0.1, -0.2, 0.05, 0.0, 0.3, -0.1;
  const ResolvedRateResult result =
      solve_resolved_rate(jacobian, twist, Eigen::VectorXd::Zero(7), wide_limits());
  EXPECT_TRUE((jacobian * result.joint_velocity_rad_per_s).isApprox(twist, 1e-9));
  EXPECT_DOUBLE_EQ(result.speed_scale, 1.0);
  EXPECT_EQ(result.joints_limited, 0);
  // Minimum norm: the two joints along x share the work.
  EXPECT_NEAR(result.joint_velocity_rad_per_s[0], 0.05, 1e-9);
  EXPECT_NEAR(result.joint_velocity_rad_per_s[6], 0.05, 1e-9);
}

TEST(ResolvedRate, JointAtItsLimitStopsAndTheOthersTakeOver) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Vector6d twist = Vector6d::Zero();
  twist[0] = 0.1;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  q[0] = 3.0;  // at its upper limit
  const ResolvedRateResult result =
      solve_resolved_rate(jacobian, twist, q, wide_limits(), no_avoidance());
  EXPECT_NEAR(result.joint_velocity_rad_per_s[0], 0.0, 1e-12);
  EXPECT_NEAR(result.joint_velocity_rad_per_s[6], 0.1, 1e-9);
  EXPECT_EQ(result.joints_limited, 1);
  EXPECT_TRUE((jacobian * result.joint_velocity_rad_per_s).isApprox(twist, 1e-9));
}

TEST(ResolvedRate, NearALimitTheJointNeverOutrunsItsBrakingDistance) {
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(6, 1);
  jacobian(0, 0) = 1.0;
  ResolvedRateLimits limits = wide_limits(1);
  Vector6d twist = Vector6d::Zero();
  twist[0] = 0.9;
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 3.0 - 0.01);  // 0.01 rad of room
  const ResolvedRateResult result = solve_resolved_rate(jacobian, twist, q, limits, no_avoidance());
  EXPECT_LE(result.joint_velocity_rad_per_s[0], std::sqrt(2.0 * 5.0 * 0.01) + 1e-12);
  EXPECT_GT(result.joint_velocity_rad_per_s[0], 0.0);
  // Moving away from the limit is not restricted.
  const ResolvedRateResult away = solve_resolved_rate(jacobian, -twist, q, limits, no_avoidance());
  EXPECT_NEAR(away.joint_velocity_rad_per_s[0], -0.9, 1e-6);
}

TEST(ResolvedRate, SpeedLimitScalesAllJointsAndKeepsTheDirection) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Vector6d twist;
  twist << 0.2, 0.0, 0.0, 4.0, 0.5, 0.0;  // joint 3 would need 4 rad/s, limit 1
  const ResolvedRateResult result =
      solve_resolved_rate(jacobian, twist, Eigen::VectorXd::Zero(7), wide_limits());
  EXPECT_NEAR(result.speed_scale, 0.25, 1e-9);
  EXPECT_LE(result.joint_velocity_rad_per_s.cwiseAbs().maxCoeff(), 1.0 + 1e-12);
  const Vector6d achieved = jacobian * result.joint_velocity_rad_per_s;
  EXPECT_TRUE(achieved.isApprox(0.25 * twist, 1e-9));
}

TEST(ResolvedRate, StaysBoundedAtASingularity) {
  Eigen::MatrixXd jacobian = redundant_jacobian();
  jacobian.row(5).setZero();  // no joint can rotate about z
  jacobian(5, 5) = 1e-9;
  Vector6d twist = Vector6d::Zero();
  twist[5] = 1.0;
  const ResolvedRateResult result =
      solve_resolved_rate(jacobian, twist, Eigen::VectorXd::Zero(7), wide_limits());
  EXPECT_TRUE(result.damped);
  EXPECT_TRUE(result.joint_velocity_rad_per_s.allFinite());
  EXPECT_LE(result.joint_velocity_rad_per_s.cwiseAbs().maxCoeff(), 1.0 + 1e-12);
}

TEST(ResolvedRate, NullSpacePushesAJointOutOfItsLimitMarginWithoutMovingTheTool) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  q[6] = 2.9;  // inside the 8 % margin of its +3 limit
  Vector6d twist = Vector6d::Zero();
  twist[1] = 0.1;
  const ResolvedRateResult result = solve_resolved_rate(jacobian, twist, q, wide_limits());
  EXPECT_LT(result.joint_velocity_rad_per_s[6], 0.0);
  EXPECT_TRUE((jacobian * result.joint_velocity_rad_per_s).isApprox(twist, 1e-6));
}

TEST(ResolvedRate, BadInputGivesZeroVelocity) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Vector6d twist = Vector6d::Ones();
  EXPECT_TRUE(solve_resolved_rate(jacobian, twist, Eigen::VectorXd::Zero(6), wide_limits())
                  .joint_velocity_rad_per_s.isZero());
  twist[2] = std::nan("");
  EXPECT_TRUE(solve_resolved_rate(jacobian, twist, Eigen::VectorXd::Zero(7), wide_limits())
                  .joint_velocity_rad_per_s.isZero());
  EXPECT_TRUE(solve_resolved_rate(Eigen::MatrixXd::Zero(5, 7), Vector6d::Ones(),
                                  Eigen::VectorXd::Zero(7), wide_limits())
                  .joint_velocity_rad_per_s.isZero());
}

TEST(ResolvedRate, DampedLeastSquaresMatchesThePseudoInverseWithoutDamping) {
  const Eigen::MatrixXd jacobian = redundant_jacobian();
  Vector6d error;
  error << 0.3, 0.1, -0.2, 0.0, 0.05, 0.4;
  const Eigen::VectorXd step = damped_least_squares(jacobian, error, 0.0);
  EXPECT_TRUE((jacobian * step).isApprox(error, 1e-8));
  const Eigen::VectorXd damped = damped_least_squares(jacobian, error, 1.0);
  EXPECT_LT(damped.norm(), step.norm());
}

}  // namespace
}  // namespace rigger::sim
