#pragma once
/// @file
/// Pick and Place: the classic robot pick and place of an object within the robot's payload, with the
/// magnetic gripper (docs/skills.md). The simulated cell has no such small object (its load weighs
/// 40 kg and hangs from the crane: AttachRobotToLoad); these skills are unit-tested with fakes.
///
/// Pick:  check ─▶ resolve ─▶ move_approach ─▶ descend ─▶ grip ─▶ await_hold ─▶ retreat ─▶ verify ─▶ SUCCESS
/// Place: check ─▶ resolve ─▶ move_approach ─▶ descend ─▶ release ─▶ confirm_released ─▶ retreat ─▶ SUCCESS
///
/// The approach pose is the grasp (place) pose moved back along the tool's −z by approach_m; move_approach
/// goes there at speed_scale, descend is the straight line to the grasp (place) pose at
/// approach_speed_m_per_s, retreat the straight line back by retreat_m (skipped when 0).
///
/// Safe stops: move_approach, descend and retreat stop the robot (MOTION_STOP, safe at rest); the other
/// states move nothing. A safe stop never switches the magnet.
///
/// Pick failure codes: DEVICE_UNAVAILABLE, GRIPPER_STATE_STALE, GRIPPER_OCCUPIED (already holding),
/// UNKNOWN_FEATURE / WORLD_UNREACHABLE / NOT_LOCALIZED / NOT_VERIFIABLE, PLAN_FAILED, MOTION_FAILED /
/// MOTION_ABORTED, GRIPPER_TIMEOUT, GRASP_FAILED, GRASP_LOST, TIMEOUT.
/// Place failure codes: DEVICE_UNAVAILABLE, GRIPPER_STATE_STALE, NOT_HOLDING, UNKNOWN_FEATURE /
/// WORLD_UNREACHABLE / NOT_LOCALIZED / NOT_VERIFIABLE (a feature frame), PLAN_FAILED, MOTION_FAILED /
/// MOTION_ABORTED, GRIPPER_TIMEOUT, RELEASE_FAILED, TIMEOUT.

#include "gripper_skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

/// The straight approach of Pick and Place: at most this long, with the tool orientation unchanged.
inline constexpr double kPickPlaceMaxApproachM = 0.5;

class PickSkill final : public GripperSkill {
 public:
  static const skill::SkillDescription& describe();
  PickSkill();

 private:
  void check();
  void resolve();
  void move_approach();
  void descend();
  void grip();
  void await_hold();
  void retreat();
  void verify();

  Eigen::Isometry3d grasp_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d approach_ = Eigen::Isometry3d::Identity();
};

class PlaceSkill final : public GripperSkill {
 public:
  static const skill::SkillDescription& describe();
  PlaceSkill();

 private:
  void check();
  void resolve();
  void planned(const Eigen::Isometry3d& place);
  void move_approach();
  void descend();
  void release();
  void confirm_released();
  void retreat();

  PoseParam pose_;
  Eigen::Isometry3d place_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d approach_ = Eigen::Isometry3d::Identity();
};

}  // namespace rigger::skill_executor
