#pragma once
/// @file
/// AttachRobotToLoad: grasps the crane-carried load with the magnetic gripper (docs/skills.md).
///
///   check ─▶ resolve ─┬─(gripper idle)──────────────────────────▶ move_approach ─┐
///                     └─(energized/holding: a retry)─▶ release ─▶ retreat ───────┤
///   ┌────────────────────────────────────────────────────────────────────────────┘
///   └▶ energize ─▶ re_resolve ─▶ approach ─▶ await_hold ─▶ verify ─▶ confirm ─▶ SUCCESS
///
/// check: devices, the crane's health (unless check_crane = false), a fresh gripper state. resolve: the
/// grasp and approach features in the robot base frame, planned as a transfer to the approach pose plus
/// a straight approach (move_approach and approach also watch the crane's health: a fault stops the
/// robot and fails CRANE_FAULT). re_resolve: the grasp again right before the final approach (the load hangs and
/// may sway; LOAD_MOVING beyond max_sway_m). The magnet is energized at the approach pose and grips on
/// contact during the slow straight approach; the hold is verified for verify_s.
///
/// Safe stops: retreat, move_approach and approach stop the robot (MOTION_STOP, safe at rest);
/// the other states command nothing that moves. The magnet is never switched by a safe stop: a held
/// load stays held.
///
/// Failure codes: BAD_PARAMS / UNKNOWN_FEATURE / WORLD_UNREACHABLE (SkillRun and the resolver),
/// DEVICE_UNAVAILABLE, CRANE_FAULT, GRIPPER_STATE_STALE, NOT_LOCALIZED, NOT_VERIFIABLE, PLAN_FAILED,
/// LOAD_MOVING, MOTION_FAILED / MOTION_ABORTED, GRIPPER_TIMEOUT, RELEASE_FAILED, GRASP_FAILED,
/// GRASP_LOST, TIMEOUT.

#include <string>

#include "gripper_skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

class AttachRobotToLoadSkill final : public GripperSkill {
 public:
  static const skill::SkillDescription& describe();
  AttachRobotToLoadSkill();

  /// Largest angle between the approach and grasp orientations of the straight approach.
  static constexpr double kMaxApproachAngleRad = 10.0 * 3.14159265358979323846 / 180.0;
  /// Longest straight approach (approach pose to grasp pose, plus the sway allowance).
  static constexpr double kMaxApproachLengthM = 0.5;

 private:
  void check();
  void resolve();
  void release();
  void retreat();
  void move_approach();
  void energize();
  void re_resolve();
  void approach();
  void await_hold();
  void verify();
  void confirm();

  bool needs_release_ = false;
  Eigen::Isometry3d grasp_ = Eigen::Isometry3d::Identity();     // tool pose at the grasp, robot base frame
  Eigen::Isometry3d approach_ = Eigen::Isometry3d::Identity();  // tool pose at the approach waypoint
};

}  // namespace rigger::skill_executor
