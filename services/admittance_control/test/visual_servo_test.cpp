#include "visual_servo.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "control_math.hpp"
#include "rigger/base/config.hpp"

namespace rigger::control {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = kPi / 180.0;

Eigen::Isometry3d pose(const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = rotation;
  p.translation() = position;
  return p;
}

Eigen::Matrix3d rot(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

TrackedPose tracked(const Eigen::Isometry3d& p, double quality = 0.9, double age_s = 0.05) {
  return TrackedPose{p, quality, Seconds(age_s)};
}

// Insertion 0.1 m above the target's frame, as in the simulated cell; speed limits out of the way.
VisualServoConfig unlimited_config() {
  VisualServoConfig c;
  c.pose_target_load_insertion = pose(Eigen::Vector3d(0.0, 0.0, 0.1));
  c.max_linear_speed_mps.setConstant(10.0);
  c.max_angular_speed_radps.setConstant(10.0);
  return c;
}

TEST(PoseError, PureTranslation) {
  const VisualServo servo(unlimited_config());
  const ServoOutput out = servo.update(tracked(pose({0.9, 2.2, 0.3})), tracked(pose({1.0, 2.0, 0.5})));
  ASSERT_TRUE(out.tracking());
  ASSERT_TRUE(out.error_valid);
  // Goal (1.0, 2.0, 0.6) minus load (0.9, 2.2, 0.3).
  EXPECT_NEAR((out.error.translation_world_m - Eigen::Vector3d(0.1, -0.2, 0.3)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out.error.distance_m, std::sqrt(0.01 + 0.04 + 0.09), 1e-12);
  EXPECT_NEAR(out.error.angle_rad, 0.0, 1e-12);
  EXPECT_NEAR((out.twist_world.linear_mps - Eigen::Vector3d(0.05, -0.1, 0.15)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out.twist_world.angular_radps.norm(), 0.0, 1e-12);
  EXPECT_FALSE(out.converged);
}

TEST(PoseError, PureNinetyDegreeRotationAboutZ) {
  const VisualServo servo(unlimited_config());
  const Eigen::Isometry3d target = pose({1.0, 2.0, 0.5}, rot(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  const ServoOutput out = servo.update(tracked(pose({1.0, 2.0, 0.6})), tracked(target));
  EXPECT_NEAR(out.error.distance_m, 0.0, 1e-12);  // the offset is along z, which the yaw keeps
  EXPECT_NEAR((out.error.rotation_world_rad - Eigen::Vector3d(0.0, 0.0, kPi / 2.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out.error.angle_rad, kPi / 2.0, 1e-12);
  EXPECT_NEAR((out.twist_world.angular_radps - Eigen::Vector3d(0.0, 0.0, 0.25 * kPi)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out.twist_world.linear_mps.norm(), 0.0, 1e-12);
  // The other way round turns the other way.
  const ServoOutput back =
      servo.update(tracked(pose({1.0, 2.0, 0.6}, rot(kPi / 2.0, Eigen::Vector3d::UnitZ()))), tracked(pose({1.0, 2.0, 0.5})));
  EXPECT_NEAR((back.error.rotation_world_rad - Eigen::Vector3d(0.0, 0.0, -kPi / 2.0)).norm(), 0.0, 1e-12);
}

TEST(PoseError, CombinedRotationAndTranslationWithARotatedTarget) {
  // Target at (1, 2, 0) turned 90 deg about z; the insertion offset (0.1, 0, 0.1) in the target's
  // frame is (0, 0.1, 0.1) in the world: goal (1, 2.1, 0.1) with orientation Rz(90).
  // Load at (1, 2, 0.5) turned 90 deg about x. R_goal R_load^T = Rz(90) Rx(-90) =
  // [[0, 0, -1], [1, 0, 0], [0, -1, 0]]: trace 0, so 120 deg, about (-1, -1, 1) / sqrt(3).
  VisualServoConfig c = unlimited_config();
  c.pose_target_load_insertion = pose({0.1, 0.0, 0.1});
  const VisualServo servo(c);
  const ServoOutput out = servo.update(tracked(pose({1.0, 2.0, 0.5}, rot(kPi / 2.0, Eigen::Vector3d::UnitX()))),
                                       tracked(pose({1.0, 2.0, 0.0}, rot(kPi / 2.0, Eigen::Vector3d::UnitZ()))));
  EXPECT_NEAR((servo.goal(pose({1.0, 2.0, 0.0}, rot(kPi / 2.0, Eigen::Vector3d::UnitZ()))).translation() -
               Eigen::Vector3d(1.0, 2.1, 0.1))
                  .norm(),
              0.0, 1e-12);
  EXPECT_NEAR((out.error.translation_world_m - Eigen::Vector3d(0.0, 0.1, -0.4)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out.error.angle_rad, 2.0 * kPi / 3.0, 1e-12);
  const Eigen::Vector3d expected_rotation = 2.0 * kPi / 3.0 * Eigen::Vector3d(-1.0, -1.0, 1.0) / std::sqrt(3.0);
  EXPECT_NEAR((out.error.rotation_world_rad - expected_rotation).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.twist_world.angular_radps - 0.5 * expected_rotation).norm(), 0.0, 1e-12);
}

TEST(PoseError, TakesTheShortWayRound) {
  // 270 deg about z is -90 deg.
  const PoseError e = compute_pose_error(pose({0, 0, 0}), pose({0, 0, 0}, rot(1.5 * kPi, Eigen::Vector3d::UnitZ())));
  EXPECT_NEAR(e.angle_rad, kPi / 2.0, 1e-12);
  EXPECT_NEAR(e.rotation_world_rad.z(), -kPi / 2.0, 1e-12);
}

TEST(Convergence, IsReportedWithinFiveMillimetresAndOneDegree) {
  const VisualServo servo(unlimited_config());
  const Eigen::Isometry3d target = pose({3.55, 2.25, 0.95});
  const Eigen::Vector3d goal(3.55, 2.25, 1.05);
  auto converged = [&](const Eigen::Vector3d& offset, double yaw_deg) {
    return servo.update(tracked(pose(goal + offset, rot(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()))), tracked(target))
        .converged;
  };
  EXPECT_TRUE(converged({0.004, 0.0, 0.0}, 0.9));
  EXPECT_TRUE(converged({0.0, -0.003, 0.003}, -0.5));
  EXPECT_FALSE(converged({0.0051, 0.0, 0.0}, 0.0));
  EXPECT_FALSE(converged({0.0, 0.004, 0.004}, 0.0));  // 5.7 mm in norm
  EXPECT_FALSE(converged({0.0, 0.0, 0.0}, 1.1));
}

TEST(TrackingQuality, LowQualityOrOldPosesStopTheReferenceWithAReason) {
  const VisualServo servo(unlimited_config());
  const Eigen::Isometry3d load = pose({3.55, 1.75, 1.2});
  const Eigen::Isometry3d target = pose({3.55, 2.25, 0.95});
  ASSERT_GT(servo.update(tracked(load), tracked(target)).twist_world.linear_mps.norm(), 0.1);
  struct Case {
    TrackedPose load;
    TrackedPose target;
    ServoStopReason reason;
  };
  const std::vector<Case> cases{
      {tracked(load, 0.49), tracked(target), ServoStopReason::kLoadQualityLow},
      {tracked(load), tracked(target, kNaN), ServoStopReason::kTargetQualityLow},
      {tracked(load, 0.9, 0.21), tracked(target), ServoStopReason::kLoadPoseStale},
      {tracked(load), tracked(target, 0.9, -1.0), ServoStopReason::kTargetPoseStale},
      {tracked(load), tracked(target, 0.9, kNaN), ServoStopReason::kTargetPoseStale},
  };
  for (const Case& k : cases) {
    const ServoOutput out = servo.update(k.load, k.target);
    EXPECT_EQ(out.stop_reason, k.reason) << to_string(k.reason);
    EXPECT_FALSE(out.tracking());
    EXPECT_TRUE(out.twist_world.stacked().isZero(0.0));
    EXPECT_FALSE(out.converged);
    EXPECT_TRUE(out.error_valid);  // still shown to the operator
    EXPECT_NEAR(out.error.distance_m, std::hypot(0.5, 0.15), 1e-12);
  }
  EXPECT_EQ(to_string(ServoStopReason::kLoadQualityLow), "LOAD_QUALITY_LOW");
  // Quality exactly at the threshold still tracks.
  EXPECT_TRUE(servo.update(tracked(load, 0.5), tracked(target)).tracking());
}

TEST(TrackingQuality, BrokenPosesStopTheReference) {
  const VisualServo servo(unlimited_config());
  Eigen::Isometry3d nan_pose = pose({kNaN, 0.0, 0.0});
  Eigen::Isometry3d scaled = pose({1.0, 1.0, 1.0});
  scaled.linear() *= 1.01;
  ServoOutput out = servo.update(tracked(nan_pose), tracked(pose({1.0, 2.0, 0.0})));
  EXPECT_EQ(out.stop_reason, ServoStopReason::kLoadPoseInvalid);
  EXPECT_FALSE(out.error_valid);
  EXPECT_TRUE(out.twist_world.stacked().isZero(0.0));
  out = servo.update(tracked(pose({1.0, 2.0, 0.0})), tracked(scaled));
  EXPECT_EQ(out.stop_reason, ServoStopReason::kTargetPoseInvalid);
}

TEST(SpeedLimits, ScaleTheTwistKeepingItsDirection) {
  VisualServoConfig c = unlimited_config();
  c.max_linear_speed_mps = Eigen::Vector3d(0.1, 0.1, 0.05);
  c.max_angular_speed_radps = Eigen::Vector3d(0.2, 0.2, 0.2);
  const VisualServo servo(c);
  // Error (0, 0.5, -0.15) m: unlimited (0, 0.25, -0.075); y's limit scales it by 0.4.
  const ServoOutput out = servo.update(tracked(pose({3.55, 1.75, 1.20})), tracked(pose({3.55, 2.25, 0.95})));
  EXPECT_TRUE(out.speed_limited);
  EXPECT_NEAR((out.twist_world.linear_mps - Eigen::Vector3d(0.0, 0.1, -0.03)).norm(), 0.0, 1e-12);
  const ServoOutput turning = servo.update(tracked(pose({3.55, 2.25, 1.05}, rot(kPi / 2.0, Eigen::Vector3d::UnitZ()))),
                                           tracked(pose({3.55, 2.25, 0.95})));
  EXPECT_NEAR(turning.twist_world.angular_radps.z(), -0.2, 1e-12);
}

TEST(KinematicLoop, AnIdealRigidLoadConvergesFromHalfAMetre) {
  // The load follows the reference exactly: e' = -k e, saturated at first. It must arrive within
  // tolerance and report it.
  VisualServoConfig c;
  c.pose_target_load_insertion = pose({0.0, 0.0, 0.1});
  const VisualServo servo(c);
  const Eigen::Isometry3d target = pose({3.55, 2.25, 0.95});
  Eigen::Isometry3d load = pose({3.55, 1.75, 1.2}, rot(10.0 * kDeg, Eigen::Vector3d(0.2, 0.1, 1.0)));
  const double h = 1.0 / 30.0;
  double t = 0.0;
  ServoOutput out;
  for (; t < 60.0; t += h) {
    out = servo.update(tracked(load), tracked(target));
    if (out.converged) break;
    load.translation() += out.twist_world.linear_mps * h;
    const Eigen::Vector3d w = out.twist_world.angular_radps;
    if (w.norm() > 0.0)
      load.linear() = (Eigen::AngleAxisd(w.norm() * h, w.normalized()) * Eigen::Quaterniond(load.linear())).toRotationMatrix();
  }
  EXPECT_TRUE(out.converged);
  EXPECT_LT(t, 20.0);
  EXPECT_LE(out.error.distance_m, 0.005);
  EXPECT_LE(out.error.angle_rad, 1.0 * kDeg);
}

TEST(Config, ConstructorRefusesBadSettings) {
  VisualServoConfig c;
  c.min_quality = 1.5;
  try {
    VisualServo servo(c);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/min_quality");
  }
  c = VisualServoConfig{};
  c.linear_gain_per_s.y() = -0.1;
  EXPECT_THROW(VisualServo{c}, ConfigError);
  c = VisualServoConfig{};
  c.pose_target_load_insertion.linear() *= 2.0;
  EXPECT_THROW(VisualServo{c}, ConfigError);
}

}  // namespace
}  // namespace rigger::control
