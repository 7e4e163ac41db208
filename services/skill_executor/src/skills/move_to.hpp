#pragma once
/// @file
/// MoveTo: the worked example of docs/skills.md. Moves the robot's tool to a Cartesian goal.
///
///   plan ──ok──▶ move ──MOTION_SUCCEEDED──▶ verify ──at goal──▶ SUCCESS
///    │            │                            │
///    ▼            ▼ (failed / timeout)         ▼ (stale state / off goal)
///  FAILURE      FAILURE (after stop)         FAILURE
///
/// Safe stops: plan → nothing commanded; move → MOTION_STOP, safe once the arm is at rest;
/// verify → nothing commanded (the motion has ended).
///
/// Params: goal (pose in the robot base frame "robot", the default when it names none), speed_scale
/// (0.01–1, default 0.2), timeout_s (default 30 s), position_tolerance_m (default 5 mm), max_reach_m
/// (default 1.2 m: goals farther from the robot base are refused by the planner). Claims "robot".
/// Failure codes: DEVICE_UNAVAILABLE, PLAN_FAILED (other frame, non-finite, out of reach), the motion's (MOTION_FAILED, MOTION_ABORTED,
/// TIMEOUT), ROBOT_STATE_STALE, NOT_VERIFIABLE (goal and robot state in different frames), NOT_AT_GOAL.

#include <optional>
#include <string>

#include "rigger/skill_sdk/pose_param.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

/// The robot base frame: the robot entity of the world model, the frame of rigger/robot/state.
inline constexpr const char* kRobotBaseFrame = "robot";

/// The synchronous planning primitive of MoveTo: checks a Cartesian goal is in the robot base frame,
/// finite and within reach.
/// Returns an error text, or std::nullopt when the goal can be commanded.
std::optional<std::string> plan_cartesian_goal(const PoseParam& goal, double max_reach_m);

class MoveToSkill final : public Skill {
 public:
  static const skill::SkillDescription& describe();
  MoveToSkill();

  /// Time the safe stop may take before it counts as failed.
  static constexpr std::chrono::seconds kStopTimeout{3};
  /// How long verify waits for a fresh robot state.
  static constexpr std::chrono::seconds kStateTimeout{1};

 private:
  void plan();
  void move();
  void verify();
  void stop_robot(const SafeStopDone& done);

  PoseParam goal_;
};

}  // namespace rigger::skill_executor
