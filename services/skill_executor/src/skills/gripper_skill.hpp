#pragma once
/// @file
/// The shared steps of the gripper skills (AttachRobotToLoad, Release, Pick, Place): a base class
/// with the asynchronous primitives each of them chains — resolve a feature in the robot base frame,
/// a Cartesian tool motion, a gripper command, a wait on the gripper state, a fresh robot state — each
/// started in the current state (guarded, tracked) and failing the run with the primitive's code.
/// Also: the run's overall timeout (`timeout_s` → TIMEOUT from whatever state the skill is in), and
/// the robot safe stop.
///
/// Frames: every pose here is the tool (magnet face centre, z out of the face) in the robot base frame
/// "robot", the frame of rigger/robot/state and of rigger/robot/cmd_motion goals.
/// Thread safety: none; the executor's event loop thread (as Skill).

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rigger/skill_sdk/skill.hpp"
#include "move_to.hpp"
#include "rigger/skill/param_spec.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

/// The robot's Cartesian tool speed at speed_scale 1 (the iiwa of cell_sim: 0.5 m/s). Skills take tool
/// speeds in m/s and command speed_scale = speed / this.
inline constexpr double kRobotMaxToolSpeedMps = 0.5;

/// speed_scale for a tool speed in m/s, clamped to [0.001, 1].
double speed_scale_for(double tool_speed_mps);

/// A length for messages, rounded to whole millimetres: "12 mm".
std::string mm(double m);

/// The description of a gripper skill: kind skill, pausable, claiming robot, gripper and $object, with
/// `preconditions` and `postconditions` as predicate texts ("localized($object)").
/// @throws std::logic_error naming a predicate that does not parse.
skill::SkillDescription gripper_skill_description(std::string name, std::string description,
                                                  std::vector<skill::ParamSpec> params,
                                                  const std::vector<std::string>& preconditions,
                                                  const std::vector<std::string>& postconditions);

/// The parameters the gripper skills share: `max_reach_m` (m, [0.1, 5], default 1.2; farther tool poses are
/// refused by the planner) and `timeout_s` (s, [1, 600], default 60; the whole skill).
skill::ParamSpec max_reach_param();
skill::ParamSpec timeout_param();

/// `pose` moved by `distance_m` along its own z axis (negative: back, away from the face).
Eigen::Isometry3d along_tool_z(const Eigen::Isometry3d& pose, double distance_m);

/// Checks a straight approach from `from` to `to` (both tool poses in the robot base frame): finite,
/// within `max_reach_m` of the base, no longer than `max_length_m`, and the same tool orientation within
/// `max_angle_rad` (a straight approach does not turn the face). Returns an error text or std::nullopt.
std::optional<std::string> check_straight_approach(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to,
                                                   double max_reach_m, double max_length_m, double max_angle_rad);

class GripperSkill : public CraneSkill {
 public:
  ~GripperSkill() override;

  /// Time the robot's safe stop may take before it counts as failed.
  static constexpr std::chrono::seconds kStopTimeout{3};
  /// How long a gripper command may take to be confirmed, and a wait for a fresh state sample.
  static constexpr std::chrono::seconds kGripperTimeout{2};
  static constexpr std::chrono::seconds kStateTimeout{1};
  /// How long a feature resolution may take.
  static constexpr std::chrono::seconds kResolveTimeout{2};

 protected:
  GripperSkill() = default;

  /// Adds a state that may have the robot moving: its safe stop and its pause hold are stop_robot().
  void add_motion_state(std::string name, std::function<void()> on_enter);
  /// Fails DEVICE_UNAVAILABLE naming the first missing device; true when all needed are there.
  bool require_devices(bool robot, bool gripper, bool world);
  /// Starts the overall timeout: after `timeout_s` the run fails TIMEOUT from its current state (after
  /// that state's safe stop). Call once, from the first state. It does not count while the run is
  /// paused, and counts afresh from the resume.
  void start_overall_timeout(double timeout_s);
  void on_run_paused() override;
  void on_run_resumed() override;

  /// When `required`: the crane's health (CraneMonitor::check_health) on a crane state published after the
  /// check began, waiting up to 2 s for it: a grasp or a release decides on the crane as it is, not on a
  /// state from before a fault the gateway has reported since. `then` when healthy, else CRANE_FAULT, or
  /// DEVICE_UNAVAILABLE without a crane device. When not required: `then` at once.
  void check_crane(bool required, std::function<void()> then);
  /// When `required`: watches the crane's health for the rest of the current state (a bad crane state,
  /// or none for 1 s, fails CRANE_FAULT after the state's safe stop, e.g. stopping the robot).
  void watch_crane(bool required);
  /// Resolves `ref` in the robot base frame; fails with the resolver's code (UNKNOWN_FEATURE,
  /// WORLD_UNREACHABLE, …) or NOT_LOCALIZED when the entity has not been localized.
  void resolve_in_robot_frame(const std::string& ref, std::function<void(const Eigen::Isometry3d&)> then);
  /// Moves the tool in a straight line to `pose_robot_tool` (robot base frame); `then` on success; fails
  /// with the motion's code (MOTION_FAILED, MOTION_ABORTED, TIMEOUT) otherwise.
  void move_tool(const Eigen::Isometry3d& pose_robot_tool, double speed_scale, std::chrono::nanoseconds timeout,
                 std::function<void()> then);
  /// Energizes or releases the magnet; `then` once confirmed; fails GRIPPER_TIMEOUT otherwise.
  void set_magnet(bool energize, std::function<void()> then);
  /// Waits for a gripper state satisfying `predicate`: `on_sample` with it, `on_timeout` after `timeout`.
  void wait_gripper(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                    std::function<void(const GripperSnapshot&)> on_sample, std::function<void()> on_timeout);
  /// The magnet de-energized: `then` once a gripper state reports neither energized nor holding; else
  /// RELEASE_FAILED after kGripperTimeout.
  void wait_released(std::function<void()> then);
  /// The magnet reports holding within `timeout_s` → `then`; else GRASP_FAILED ("… within T s" and
  /// `since`, e.g. " of reaching the grasp frame").
  void wait_for_hold(double timeout_s, const std::string& since, std::function<void()> then);
  /// The next gripper state sample; fails GRIPPER_STATE_STALE when none comes within kStateTimeout.
  void read_gripper(std::function<void(const GripperSnapshot&)> then);
  /// The next robot state sample in the robot base frame; fails ROBOT_STATE_STALE when none comes within
  /// kStateTimeout, NOT_VERIFIABLE when it is in another frame, ROBOT_FAULT when the robot reports one.
  void read_robot(std::function<void(const RobotSnapshot&)> then);

  /// The safe stop of a state that may have the robot moving: MOTION_STOP, safe once at rest. The
  /// magnet is left as it is (a safe stop never releases a held load).
  void stop_robot(const SafeStopDone& done);

  /// The timeout of one motion: the overall timeout (which ends the run first, as TIMEOUT).
  std::chrono::nanoseconds motion_timeout() const { return overall_timeout_; }

 private:
  void arm_overall_timeout();

  std::uint64_t overall_timer_ = 0;
  std::chrono::nanoseconds overall_timeout_{std::chrono::seconds(60)};
  double overall_timeout_s_ = 60.0;
  bool overall_held_ = false;  ///< the overall timer was cancelled by a pause: re-armed on resume
};

}  // namespace rigger::skill_executor
