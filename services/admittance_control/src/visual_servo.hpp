#pragma once
/// @file
/// Position-based visual servo (PBVS). From the tracked poses of the load and the target (world
/// frame) and the insertion offset from the CAD features (the load's pose in the target's frame when
/// inserted), it computes the pose error and a reference twist that drives the load to its insertion
/// pose:
///
///     pose_world_goal = pose_world_target * pose_target_load_insertion
///     e_t = p_goal - p_load                       (world, m)
///     e_r = log(R_goal * R_load^T)                (world, axis * angle, rad; angle in [0, pi])
///     v = k_t .* e_t,  w = k_r .* e_r             (then per-axis speed limits, direction kept)
///
/// The twist is the load's: v is the velocity of the load frame's origin and w its angular velocity,
/// both in the world frame. With this choice the origin moves on a straight line and the rotation
/// follows the geodesic, decoupled. A robot holding the load commands the same motion at its TCP as
/// shift_twist(twist, p_tcp - p_load).
///
/// The reference stops (zero twist, reason reported) when either pose's quality is below
/// min_quality, either pose is older than max_pose_age, or a pose is not a finite rigid transform.
/// Converged is reported when |e_t| <= translation_tolerance_m and angle <= rotation_tolerance_rad;
/// the servo keeps correcting while converged (the caller decides to stop).
/// Pure C++ and Eigen: no DDS, no logging. update() is const and never throws; the constructor throws
/// rigger::ConfigError.

#include <optional>
#include <string_view>

#include <Eigen/Geometry>

#include "control_types.hpp"

namespace rigger::control {

/// Setup-time configuration of VisualServo.
struct VisualServoConfig {
  /// The load's pose in the target's frame when inserted (CAD feature `insertion.pose_in_target`).
  Eigen::Isometry3d pose_target_load_insertion = Eigen::Isometry3d::Identity();
  /// Proportional gains per world axis, 1/s, >= 0 (1/gain is the time constant of the approach).
  Eigen::Vector3d linear_gain_per_s{0.5, 0.5, 0.5};
  Eigen::Vector3d angular_gain_per_s{0.5, 0.5, 0.5};
  /// Speed limits per world axis, m/s and rad/s, >= 0 (the twist is scaled, its direction kept).
  Eigen::Vector3d max_linear_speed_mps{0.10, 0.10, 0.05};
  Eigen::Vector3d max_angular_speed_radps{0.2, 0.2, 0.2};
  /// Convergence tolerance, m and rad (defaults 5 mm and 1 degree).
  double translation_tolerance_m = 0.005;
  double rotation_tolerance_rad = 1.0 * 3.14159265358979323846 / 180.0;
  /// Tracking quality below this (quality in [0, 1]) stops the reference.
  double min_quality = 0.5;
  /// A pose older than this stops the reference.
  Seconds max_pose_age{0.2};
};

/// The first rule `config` breaks (pointer relative to the configuration object), if any.
std::optional<ConfigProblem> find_problem(const VisualServoConfig& config);

/// A tracked 6D pose.
struct TrackedPose {
  Eigen::Isometry3d pose_world = Eigen::Isometry3d::Identity();  ///< object frame in the world
  double quality = 0.0;                                          ///< tracker quality in [0, 1]
  Seconds age{0.0};                                              ///< now minus the image's stamp
};

/// How far the load is from where it should be.
struct PoseError {
  Eigen::Vector3d translation_world_m = Eigen::Vector3d::Zero();  ///< goal origin minus load origin
  Eigen::Vector3d rotation_world_rad = Eigen::Vector3d::Zero();   ///< axis * angle of R_goal R_load^T
  double distance_m = 0.0;                                        ///< |translation|
  double angle_rad = 0.0;                                         ///< rotation angle, [0, pi]
};

/// The pose error of `pose_world_load` with respect to `pose_world_goal` (see the file comment).
PoseError compute_pose_error(const Eigen::Isometry3d& pose_world_load, const Eigen::Isometry3d& pose_world_goal);

/// Why the reference is zero.
enum class ServoStopReason {
  kNone,
  kLoadQualityLow,    ///< LOAD_QUALITY_LOW
  kTargetQualityLow,  ///< TARGET_QUALITY_LOW
  kLoadPoseStale,     ///< LOAD_POSE_STALE
  kTargetPoseStale,   ///< TARGET_POSE_STALE
  kLoadPoseInvalid,   ///< LOAD_POSE_INVALID: non-finite or not a rigid transform
  kTargetPoseInvalid, ///< TARGET_POSE_INVALID
};
/// The reason code, e.g. "LOAD_QUALITY_LOW" ("NONE" for kNone).
std::string_view to_string(ServoStopReason reason);

struct ServoOutput {
  /// Reference twist of the load (origin velocity, angular velocity), world frame; zero when stopped.
  Twist twist_world;
  /// The pose error, computed whenever both poses are finite rigid transforms (also when the
  /// reference is stopped for low quality or age, for display); error_valid says whether it was.
  PoseError error;
  bool error_valid = false;
  bool converged = false;            ///< within tolerance (only with usable poses)
  bool speed_limited = false;        ///< the twist was scaled down to the speed limits
  ServoStopReason stop_reason = ServoStopReason::kNone;
  /// True when the twist is a reference to follow (stop_reason == kNone).
  bool tracking() const { return stop_reason == ServoStopReason::kNone; }
};

/// The position-based visual servo (see the file comment).
class VisualServo {
 public:
  /// @throws rigger::ConfigError (file "VisualServoConfig") when `config` breaks a rule.
  explicit VisualServo(VisualServoConfig config);

  /// Where the load should be given the target's pose: pose_world_target * insertion offset.
  Eigen::Isometry3d goal(const Eigen::Isometry3d& pose_world_target) const;

  /// The reference twist and the error for these tracked poses; never throws.
  ServoOutput update(const TrackedPose& load, const TrackedPose& target) const;

  const VisualServoConfig& config() const { return config_; }

 private:
  VisualServoConfig config_;
};

}  // namespace rigger::control
