#pragma once
/// @file
/// Release: lets go of what the magnet holds and retreats (docs/skills.md).
///
///   check ──▶ release ──▶ confirm_released ──▶ read_pose ──▶ retreat ──▶ SUCCESS
///                                                  (retreat_m = 0: SUCCESS after confirm_released)
///
/// check: devices, the crane's health (unless check_crane = false: the load must hang from a healthy
/// crane before the magnet lets go), and a fresh gripper state that is energized or holding (else
/// NOT_HOLDING: nothing to release). release: de-energize, confirmed by the driver. confirm_released: a
/// state sample with neither energized nor holding (else RELEASE_FAILED). retreat: straight back along
/// the tool −z by retreat_m from where the tool is.
///
/// Safe stops: retreat stops the robot (MOTION_STOP, safe at rest); the other states move nothing.
/// Failure codes: DEVICE_UNAVAILABLE, CRANE_FAULT, GRIPPER_STATE_STALE, NOT_HOLDING, GRIPPER_TIMEOUT,
/// RELEASE_FAILED, ROBOT_STATE_STALE, NOT_VERIFIABLE, ROBOT_FAULT, PLAN_FAILED, MOTION_FAILED /
/// MOTION_ABORTED, TIMEOUT.

#include "gripper_skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

class ReleaseSkill final : public GripperSkill {
 public:
  static const skill::SkillDescription& describe();
  ReleaseSkill();

 private:
  void check();
  void release();
  void confirm_released();
  void read_pose();
  void retreat();

  Eigen::Isometry3d retreat_goal_ = Eigen::Isometry3d::Identity();
};

}  // namespace rigger::skill_executor
