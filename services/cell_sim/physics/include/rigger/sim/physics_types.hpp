#pragma once
// Value types of the cell physics API: commands' results and the state snapshots it reports.
// Units are SI; every pose and vector names its frame.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <string>

namespace rigger::sim {

/// Number of joints of the arm (KUKA LBR iiwa 14 R820).
inline constexpr int kArmJointCount = 7;

/// One value per arm joint, A1 first (rad, rad/s, N m as named by the field).
using JointVector = Eigen::Matrix<double, kArmJointCount, 1>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// A twist: linear velocity of a point and angular velocity, both in the frame the name gives.
struct Twist {
  Eigen::Vector3d linear_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rad_per_s = Eigen::Vector3d::Zero();
};

/// A wrench: force and torque about a reference point, both in the frame the name gives.
struct Wrench {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nm = Eigen::Vector3d::Zero();
};

/// Why a command was refused; `Accepted` when it was taken.
enum class CommandStatus {
  Accepted,
  RejectedNonFinite,    ///< NaN or infinite number in the command
  RejectedOutOfRange,   ///< outside joint limits, axis range or a sane magnitude
  RejectedUnreachable,  ///< no joint configuration reaches the pose (IK failed)
  RejectedHeld,         ///< the object is held (by the magnet) or carried (on the crane's rope)
  RejectedNotFree,      ///< the object is unknown or static: it moves only with a model built anew
};

/// Result of a command: status and a human-readable reason when refused.
struct CommandResult {
  CommandStatus status = CommandStatus::Accepted;
  std::string message;
  /// Motion commands: the id that `RobotState::motion` will report for this motion (0 otherwise).
  std::uint64_t motion_id = 0;

  [[nodiscard]] bool ok() const { return status == CommandStatus::Accepted; }
};

/// The crane's axes, in the order used by every crane vector: bridge (x), trolley (y), hoist.
enum class CraneAxis { Bridge = 0, Trolley = 1, Hoist = 2 };

/// Snapshot of the crane.  Axis vectors are (bridge x m, trolley y m, rope length m) in the crane
/// frame; the hoist's position is the rope paid out by the drum (positive = longer rope = load
/// lower), as its encoder would measure.
struct CraneState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  /// The velocity setpoints last accepted (zero while frozen).
  Eigen::Vector3d velocity_setpoint_mps = Eigen::Vector3d::Zero();
  /// Axis ranges of the cell geometry (min, max per axis), for limit-switch emulation.
  Eigen::Vector3d range_min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d range_max_m = Eigen::Vector3d::Zero();
  bool frozen = false;
  /// Rope tension at the hook (N), instantaneous; zero when the rope is slack.
  double rope_tension_n = 0.0;
  /// Load mass as a hoist load cell reports it: tension / g minus the hook block, low-pass
  /// filtered (time constant 0.5 s).  Drops when something else carries the load.
  double load_mass_estimate_kg = 0.0;
  bool rope_slack = false;
  /// Sway angles of the rope from the vertical: rotation about crane x, then about crane y (rad).
  Eigen::Vector2d sway_angle_rad = Eigen::Vector2d::Zero();
  Eigen::Vector2d sway_rate_rad_per_s = Eigen::Vector2d::Zero();
  /// Distance from the sheave to the hook along the rope (m): the paid-out rope plus stretch, or
  /// less when slack.
  double hook_distance_m = 0.0;
  Eigen::Vector3d position_world_hook_m = Eigen::Vector3d::Zero();
};

/// What the arm's controller is doing.
enum class RobotMode {
  Hold,             ///< holding the last reference
  JointMotion,      ///< point-to-point in joint space
  CartesianMotion,  ///< straight-line tool motion
  Twist,            ///< resolved-rate Cartesian velocity streaming
  Stopping,         ///< decelerating to rest
};

/// Status of the latest point-to-point motion.
enum class MotionStatus {
  Idle,  ///< no motion commanded yet
  Running,
  Reached,  ///< reference finished and the tool (or joints) settled at the goal
  Failed,   ///< aborted: see the message (path not trackable, did not settle)
  Stopped,  ///< stopped by stop(), a twist command or a newer motion
};

struct MotionState {
  std::uint64_t id = 0;
  MotionStatus status = MotionStatus::Idle;
  std::string message;
};

/// Snapshot of the arm.  Base frame = the robot's mounting flange frame (cell JSON "robot" pose);
/// flange frame at the iiwa's media flange; tool frame at the magnet's face centre, same axes as
/// the flange (z out of the face).
struct RobotState {
  JointVector position_rad = JointVector::Zero();
  JointVector velocity_rad_per_s = JointVector::Zero();
  JointVector torque_nm = JointVector::Zero();  ///< commanded motor torques
  JointVector reference_position_rad = JointVector::Zero();
  JointVector reference_velocity_rad_per_s = JointVector::Zero();
  Eigen::Isometry3d pose_world_base = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_world_flange = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_world_tool = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_base_flange = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_base_tool = Eigen::Isometry3d::Identity();
  /// Velocity of the tool point and angular velocity, in the base frame.
  Twist twist_base_tool;
  RobotMode mode = RobotMode::Hold;
  MotionState motion;
};

/// Phases of the magnetic gripper.
enum class GripperPhase {
  Off,        ///< not energized
  Searching,  ///< energized, not holding: grips as soon as the face is flat on the load
  Holding,    ///< holding the load
  Slipped,    ///< lost the load under overload; grips again once the face has left the load
};

struct GripperState {
  bool energized = false;
  bool holding = false;
  /// The face touches the load flat enough to grip (within 5 degrees).
  bool in_contact = false;
  GripperPhase phase = GripperPhase::Off;
  /// Current holding force (N): the cell JSON's, or what fault injection set.
  double holding_force_n = 0.0;
  /// Share of the holding capacity in use (0 = no load, >= 1 = slips), low-pass filtered.
  double utilisation = 0.0;
  /// Number of times the grip was lost under overload since start.
  std::uint64_t slip_count = 0;
};

/// Health and speed of the simulation.
struct PhysicsDiagnostics {
  std::uint64_t steps = 0;
  /// MuJoCo warnings raised since start (instability, contact buffer full, ...); 0 when healthy.
  int mujoco_warning_count = 0;
  std::string last_mujoco_warning;
  /// Simulated time divided by the wall time spent stepping, over the whole run.
  double measured_real_time_factor = 0.0;
  /// Steps per wall second while stepping.
  double steps_per_second = 0.0;
};

}  // namespace rigger::sim
