#include "visual_servo.hpp"

#include <cmath>
#include <utility>

#include "config_checks.hpp"
#include "control_math.hpp"
#include "rigger/base/config.hpp"

namespace rigger::control {
namespace {

// A pose whose rotation is further than this from orthonormal is a producer's bug, not rounding.
constexpr double kRotationTolerance = 1e-6;

bool is_rigid(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d r = pose.linear();
  if (!r.allFinite() || !pose.translation().allFinite()) return false;
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= kRotationTolerance &&
         r.determinant() > 0.0;
}

}  // namespace

std::string_view to_string(ServoStopReason reason) {
  switch (reason) {
    case ServoStopReason::kNone: return "NONE";
    case ServoStopReason::kLoadQualityLow: return "LOAD_QUALITY_LOW";
    case ServoStopReason::kTargetQualityLow: return "TARGET_QUALITY_LOW";
    case ServoStopReason::kLoadPoseStale: return "LOAD_POSE_STALE";
    case ServoStopReason::kTargetPoseStale: return "TARGET_POSE_STALE";
    case ServoStopReason::kLoadPoseInvalid: return "LOAD_POSE_INVALID";
    case ServoStopReason::kTargetPoseInvalid: return "TARGET_POSE_INVALID";
  }
  return "?";
}

std::optional<ConfigProblem> find_problem(const VisualServoConfig& c) {
  if (!is_rigid(c.pose_target_load_insertion))
    return ConfigProblem{"/pose_target_load_insertion", "expected a finite rigid transform"};
  if (auto p = check_axes(c.linear_gain_per_s, "/linear_gain_per_s", Bound::kNonNegative, "1/s")) return p;
  if (auto p = check_axes(c.angular_gain_per_s, "/angular_gain_per_s", Bound::kNonNegative, "1/s")) return p;
  if (auto p = check_axes(c.max_linear_speed_mps, "/max_linear_speed_mps", Bound::kNonNegative, "m/s")) return p;
  if (auto p = check_axes(c.max_angular_speed_radps, "/max_angular_speed_radps", Bound::kNonNegative, "rad/s"))
    return p;
  if (auto p = check_scalar(c.translation_tolerance_m, "/translation_tolerance_m", Bound::kPositive, "m")) return p;
  if (auto p = check_scalar(c.rotation_tolerance_rad, "/rotation_tolerance_rad", Bound::kPositive, "rad")) return p;
  if (!(c.min_quality >= 0.0 && c.min_quality <= 1.0))
    return ConfigProblem{"/min_quality", "expected a number in [0, 1]"};
  return check_scalar(c.max_pose_age.count(), "/max_pose_age_s", Bound::kPositive, "s");
}

PoseError compute_pose_error(const Eigen::Isometry3d& pose_world_load, const Eigen::Isometry3d& pose_world_goal) {
  PoseError e;
  e.translation_world_m = pose_world_goal.translation() - pose_world_load.translation();
  e.distance_m = e.translation_world_m.norm();
  // Eigen's AngleAxis from a quaternion yields an angle in [0, pi] (it flips the axis when w < 0),
  // so the error always takes the short way round.
  const Eigen::Matrix3d r_error = pose_world_goal.linear() * pose_world_load.linear().transpose();
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(r_error).normalized());
  e.angle_rad = aa.angle();
  e.rotation_world_rad = aa.axis() * aa.angle();
  return e;
}

VisualServo::VisualServo(VisualServoConfig config) : config_(std::move(config)) {
  if (auto p = find_problem(config_)) throw ConfigError("VisualServoConfig", p->pointer, p->problem);
}

Eigen::Isometry3d VisualServo::goal(const Eigen::Isometry3d& pose_world_target) const {
  return pose_world_target * config_.pose_target_load_insertion;
}

ServoOutput VisualServo::update(const TrackedPose& load, const TrackedPose& target) const {
  ServoOutput out;
  if (!is_rigid(load.pose_world)) {
    out.stop_reason = ServoStopReason::kLoadPoseInvalid;
    return out;
  }
  if (!is_rigid(target.pose_world)) {
    out.stop_reason = ServoStopReason::kTargetPoseInvalid;
    return out;
  }
  out.error = compute_pose_error(load.pose_world, goal(target.pose_world));
  out.error_valid = true;

  // Written as !(x >= min) so that a NaN quality fails too.
  if (!(load.quality >= config_.min_quality)) out.stop_reason = ServoStopReason::kLoadQualityLow;
  else if (!(target.quality >= config_.min_quality)) out.stop_reason = ServoStopReason::kTargetQualityLow;
  else if (!is_fresh(load.age, config_.max_pose_age)) out.stop_reason = ServoStopReason::kLoadPoseStale;
  else if (!is_fresh(target.age, config_.max_pose_age)) out.stop_reason = ServoStopReason::kTargetPoseStale;
  if (!out.tracking()) return out;

  out.converged = out.error.distance_m <= config_.translation_tolerance_m &&
                  out.error.angle_rad <= config_.rotation_tolerance_rad;
  Eigen::Vector3d linear = config_.linear_gain_per_s.cwiseProduct(out.error.translation_world_m);
  Eigen::Vector3d angular = config_.angular_gain_per_s.cwiseProduct(out.error.rotation_world_rad);
  const bool linear_limited = limit_preserving_direction(linear, config_.max_linear_speed_mps);
  const bool angular_limited = limit_preserving_direction(angular, config_.max_angular_speed_radps);
  out.speed_limited = linear_limited || angular_limited;
  out.twist_world = Twist{linear, angular};
  return out;
}

}  // namespace rigger::control
