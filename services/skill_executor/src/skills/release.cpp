#include "release.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

const skill::SkillDescription& ReleaseSkill::describe() {
  static const skill::SkillDescription kDescription = gripper_skill_description(
      "Release",
      "De-energizes the magnetic gripper, confirms it let go and retreats the tool straight back along "
      "its -z axis by retreat_m.",
      {
        params::object("object", "The object let go of (claimed while the skill runs).", "load"),
        params::number("retreat_m").unit("m").range(0.0, 0.5).fallback(0.10).doc(
            "Distance of the straight retreat along the tool's -z axis (0: none)."),
        params::number("retreat_speed_m_per_s").unit("m/s").range(0.005, 0.25).fallback(0.05).doc(
            "Tool speed of the retreat."),
        params::number("max_reach_m").unit("m").range(0.1, 5.0).fallback(1.2).doc(
            "A retreat goal farther than this from the robot base is refused by the planner."),
        params::boolean("check_crane").fallback(true).doc(
            "Refuse to let go unless the crane reports healthy (rigger/crane/state)."),
        params::number("timeout_s").unit("s").range(1.0, 600.0).fallback(30.0).doc(
            "The whole skill; TIMEOUT (after the current state's safe stop) when it takes longer."),
      },
      {}, {"!attached(robot,$object)"});
  return kDescription;
}

ReleaseSkill::ReleaseSkill() {
  add_state({"check", [this] { check(); }, nothing_to_stop});
  add_state({"release", [this] { release(); }, nothing_to_stop});
  add_state({"confirm_released", [this] { confirm_released(); }, nothing_to_stop});
  add_state({"read_pose", [this] { read_pose(); }, nothing_to_stop});
  add_motion_state("retreat", [this] { retreat(); });
}

void ReleaseSkill::check() {
  if (!require_devices(true, true, false)) return;
  start_overall_timeout(params().at("timeout_s").get<double>());
  ctx().progress(0.0, "checking the crane and the gripper");
  check_crane(params().at("check_crane").get<bool>(), [this] {
    read_gripper([this](const GripperSnapshot& g) {
      if (!g.energized && !g.holding) {
        fail("NOT_HOLDING", "the gripper is neither energized nor holding: nothing to release");
        return;
      }
      transition("release");
    });
  });
}

void ReleaseSkill::release() {
  ctx().progress(0.2, "de-energizing the magnet");
  set_magnet(false, [this] { transition("confirm_released"); });
}

void ReleaseSkill::confirm_released() {
  wait_released([this] {
    if (params().at("retreat_m").get<double>() <= 0.0)
      succeed("released (no retreat)");
    else
      transition("read_pose");
  });
}

void ReleaseSkill::read_pose() {
  read_robot([this](const RobotSnapshot& s) {
    retreat_goal_ = along_tool_z(s.tool_pose, -params().at("retreat_m").get<double>());
    if (auto error =
            plan_cartesian_goal(PoseParam{retreat_goal_, kRobotBaseFrame}, params().at("max_reach_m").get<double>())) {
      fail("PLAN_FAILED", "retreat: " + *error);
      return;
    }
    transition("retreat");
  });
}

void ReleaseSkill::retreat() {
  ctx().progress(0.6, "retreating");
  move_tool(
      retreat_goal_, speed_scale_for(params().at("retreat_speed_m_per_s").get<double>()), motion_timeout(),
      [this] { succeed("released and retreated " + number_text(params().at("retreat_m").get<double>()) + " m"); });
}

}  // namespace rigger::skill_executor
