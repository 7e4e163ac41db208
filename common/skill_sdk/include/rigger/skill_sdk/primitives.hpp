#pragma once
/// @file
/// The primitive operations skills are built from (docs/skills.md). Synchronous primitives are plain
/// functions (planning, checks). Asynchronous primitives are device operations over topics that end
/// with exactly one callback: done (ok), failed (a code and a message) or timed out. They are
/// interfaces so that a skill's FSM is unit-tested with fakes and runs on DDS devices in the executor
/// (the SDK's DDS devices).
///
/// Thread safety: every call and every callback on the owner's event loop thread.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "rigger/base/time.hpp"

namespace rigger::skill_sdk {

/// Identifies one pending asynchronous operation; 0 is never used.
using OpId = std::uint64_t;

/// How an asynchronous operation ended.
struct OpResult {
  bool ok = false;
  std::string code;     ///< empty when ok; e.g. "MOTION_FAILED", "TIMEOUT", "WORLD_UNREACHABLE"
  std::string message;  ///< for people
  static OpResult success(std::string message = "") { return {true, "", std::move(message)}; }
  static OpResult failure(std::string code, std::string message) { return {false, std::move(code), std::move(message)}; }
};
using OpCallback = std::function<void(const OpResult&)>;

/// A point-to-point robot motion (rigger/robot/cmd_motion).
struct MotionGoal {
  enum class Kind { kJoint, kCartesian };
  Kind kind = Kind::kCartesian;
  std::vector<double> joint_goal_rad;                          ///< kJoint
  Eigen::Isometry3d pose_frame_tool = Eigen::Isometry3d::Identity();  ///< kCartesian: tool pose in `frame`
  std::string frame = "robot";  ///< the robot base frame (the world model's robot entity)
  double speed_scale = 0.2;  ///< fraction of the robot's maximum speed, (0, 1]
};

/// The robot as of its last state sample (rigger/robot/state).
struct RobotSnapshot {
  WallTime stamp;
  std::string frame;                                   ///< frame of tool_pose (the robot base)
  Eigen::Isometry3d tool_pose = Eigen::Isometry3d::Identity();
  bool moving = false;
  std::string fault;                                   ///< empty when none
};

/// The robot's motion interface.
class RobotMotion {
 public:
  virtual ~RobotMotion() = default;
  /// Starts a motion; `done` once: ok on MOTION_SUCCEEDED, else code MOTION_FAILED / MOTION_ABORTED (with
  /// the driver's code in the message) or TIMEOUT after `timeout` (the motion is then stopped).
  virtual OpId move(const MotionGoal& goal, std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Commands a stop; `done` ok once the driver reports the arm at rest, TIMEOUT otherwise.
  virtual OpId stop(std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Waits for the next robot state sample newer than now; `done` with it, or std::nullopt on timeout.
  virtual OpId next_state(std::chrono::nanoseconds timeout, std::function<void(std::optional<RobotSnapshot>)> done) = 0;
  /// Forgets a pending operation: its callback will not run. Does not stop the robot.
  virtual void cancel(OpId id) = 0;
};

/// The gripper as of one rigger/gripper/state sample.
struct GripperSnapshot {
  WallTime stamp;
  bool energized = false;  ///< the magnet is on (commanded and confirmed by the driver)
  bool contact = false;    ///< the face touches something (within the magnet's air gap)
  bool holding = false;    ///< the magnet holds an object (energized, flat on it, not slipped)
  double holding_force_n = 0.0;
  std::uint64_t last_command_seq = 0;  ///< seq of the newest rigger/gripper/cmd the driver applied
};

/// The gripper (magnetic on the simulated cell): rigger/gripper/cmd and rigger/gripper/state.
class Gripper {
 public:
  using StateCallback = std::function<void(std::optional<GripperSnapshot>)>;
  virtual ~Gripper() = default;
  /// Energizes or releases; `done` ok once the gripper reports the new state for this command,
  /// TIMEOUT otherwise.
  virtual OpId set_energized(bool energize, std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Waits for the first gripper state sample received after this call that satisfies `predicate`;
  /// `done` with it, or std::nullopt after `timeout`. E.g. "holding" (grasp confirmed), "!holding"
  /// (a loss), or `[](auto&) { return true; }` for the next sample (the driver publishes at ≥ 10 Hz
  /// and on every change, so a one-second wait without a sample means the gripper state is stale).
  virtual OpId wait_state(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                          StateCallback done) = 0;
  /// Forgets a pending operation (set_energized or wait_state): its callback will not run. The
  /// command already sent stays sent.
  virtual void cancel(OpId id) = 0;
};

/// A world-model feature resolved to a pose: e.g. "load/grasp_top" → the grasp frame in `frame`.
struct ResolvedFeature {
  std::string ref;
  std::string frame;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  bool localized = false;
  double age_s = 0.0;
};

/// Splits a feature_ref "entity/feature[/…]/id" into (entity, id); std::nullopt when it has fewer than two
/// parts. Feature ids are unique within an entity, so the middle parts only group.
std::optional<std::pair<std::string, std::string>> split_feature_ref(const std::string& ref);

/// Resolves feature_ref parameters at a skill's start (the world-model client behind it).
class FeatureResolver {
 public:
  virtual ~FeatureResolver() = default;
  /// `done` once with the feature's pose in `frame`, or a failure (UNKNOWN_FEATURE, WORLD_UNREACHABLE, …).
  virtual OpId resolve(const std::string& ref, const std::string& frame, std::chrono::nanoseconds timeout,
                       std::function<void(const OpResult&, const ResolvedFeature&)> done) = 0;
  virtual void cancel(OpId id) = 0;
};

// The cell devices of cell_devices.hpp (crane health, tracker, admittance, operator, world model).
class CraneMonitor;
class VisionTracker;
class AdmittanceController;
class OperatorPanel;
class WorldAccess;

/// The devices an executor gives its skills; a null pointer means "not configured in this executor"
/// (a skill that needs it fails with DEVICE_UNAVAILABLE).
struct Devices {
  RobotMotion* robot = nullptr;
  Gripper* gripper = nullptr;
  FeatureResolver* world = nullptr;
  CraneMonitor* crane = nullptr;              ///< rigger/crane/state, rigger/crane/control
  VisionTracker* tracker = nullptr;           ///< rigger/tracker/command, rigger/tracker/pose
  AdmittanceController* admittance = nullptr; ///< rigger/admittance/command, rigger/admittance/state
  OperatorPanel* operator_panel = nullptr;    ///< rigger/operator/prompt, rigger/operator/response
  WorldAccess* world_access = nullptr;        ///< world model features and pose updates
};

}  // namespace rigger::skill_sdk
