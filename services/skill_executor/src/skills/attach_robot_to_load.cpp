#include "attach_robot_to_load.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

const skill::SkillDescription& AttachRobotToLoadSkill::describe() {
  static const skill::SkillDescription kDescription = gripper_skill_description(
      "AttachRobotToLoad",
      "Grasps the crane-carried load with the magnetic gripper: moves the tool to the approach waypoint, energizes "
      "the magnet, re-resolves the grasp frame (the load may sway), approaches it in a straight line at low speed "
      "and verifies the hold for verify_s. A retry after a slip first releases and retreats to the approach pose.",
      {
        params::object("object", "The crane-carried object (claimed while the skill runs).", "load"),
        params::feature("grasp").doc("Grasp frame = tool pose at the grasp (z into the face), e.g. load/grasp_side."),
        params::feature("approach").doc(
            "Approach waypoint = tool pose before the straight approach, e.g. load/pre_grasp."),
        params::number("approach_speed_m_per_s").unit("m/s").range(0.005, 0.1).fallback(0.02).doc(
            "Tool speed of the straight approach (and of the retreat of a retry)."),
        params::number("press_in_m").unit("m").range(0.0, 0.03).fallback(0.01).doc(
            "How far past the grasp frame, along the tool z (into the face), the straight approach aims: the face "
            "still reaches a load that hangs or sways slightly farther away, and a hanging load yields."),
        params::number("speed_scale").range(0.01, 1.0).fallback(0.2).doc(
            "Fraction of the robot's maximum speed for the transfer to the approach waypoint."),
        params::number("verify_s").unit("s").range(0.0, 10.0).fallback(1.0).doc(
            "The magnet must report holding without interruption for this long (else GRASP_LOST)."),
        params::number("hold_timeout_s").unit("s").range(0.1, 10.0).fallback(2.0).doc(
            "After the approach ended, the magnet must report holding within this time (else GRASP_FAILED)."),
        params::number("max_sway_m").unit("m").range(0.001, 0.2).fallback(0.03).doc(
            "Largest displacement of the grasp frame between planning and the final approach (else LOAD_MOVING)."),
        max_reach_param(),
        params::boolean("check_crane").fallback(true).doc(
            "Refuse to move unless the crane reports healthy (rigger/crane/state)."),
        timeout_param(),
      },
      {"localized($object)"}, {"attached(robot,$object)"});
  return kDescription;
}

AttachRobotToLoadSkill::AttachRobotToLoadSkill() {
  add_state({"check", [this] { check(); }, nothing_to_stop});
  add_state({"resolve", [this] { resolve(); }, nothing_to_stop});
  add_state({"release", [this] { release(); }, nothing_to_stop});
  add_motion_state("retreat", [this] { retreat(); });
  add_motion_state("move_approach", [this] { move_approach(); });
  add_state({"energize", [this] { energize(); }, nothing_to_stop});
  add_state({"re_resolve", [this] { re_resolve(); }, nothing_to_stop});
  add_motion_state("approach", [this] { approach(); });
  add_state({"await_hold", [this] { await_hold(); }, nothing_to_stop});
  add_state({"verify", [this] { verify(); }, nothing_to_stop});
  add_state({"confirm", [this] { confirm(); }, nothing_to_stop});
}

void AttachRobotToLoadSkill::check() {
  if (!require_devices(true, true, true)) return;
  start_overall_timeout(params().at("timeout_s").get<double>());
  ctx().progress(0.0, "checking the crane and the gripper");
  check_crane(params().at("check_crane").get<bool>(), [this] {
    read_gripper([this](const GripperSnapshot& g) {
      needs_release_ = g.energized || g.holding;
      transition("resolve");
    });
  });
}

void AttachRobotToLoadSkill::resolve() {
  ctx().progress(0.05, "resolving the grasp and approach frames");
  const std::string grasp_ref = params().at("grasp").get<std::string>();
  const std::string approach_ref = params().at("approach").get<std::string>();
  resolve_in_robot_frame(grasp_ref, [this, approach_ref](const Eigen::Isometry3d& grasp) {
    grasp_ = grasp;
    resolve_in_robot_frame(approach_ref, [this](const Eigen::Isometry3d& approach) {
      approach_ = approach;
      if (auto error = check_straight_approach(approach_, grasp_, params().at("max_reach_m").get<double>(),
                                               kMaxApproachLengthM, kMaxApproachAngleRad)) {
        fail("PLAN_FAILED", *error);
        return;
      }
      transition(needs_release_ ? "release" : "move_approach");
    });
  });
}

void AttachRobotToLoadSkill::release() {
  // A retry after a slip: the magnet is still on (perhaps holding a corner). Let go first, so that the
  // approach starts from a released gripper; the load hangs from the crane.
  ctx().progress(0.1, "releasing the magnet before the retry");
  set_magnet(false, [this] { wait_released([this] { transition("retreat"); }); });
}

void AttachRobotToLoadSkill::retreat() {
  ctx().progress(0.15, "retreating to the approach pose");
  move_tool(approach_, speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] { transition("energize"); });
}

void AttachRobotToLoadSkill::move_approach() {
  ctx().progress(0.2, "moving to the approach pose");
  watch_crane(params().at("check_crane").get<bool>());
  move_tool(approach_, params().at("speed_scale").get<double>(), motion_timeout(), [this] { transition("energize"); });
}

void AttachRobotToLoadSkill::energize() {
  // On at the approach pose: the magnet grips at first flat contact during the approach.
  ctx().progress(0.5, "energizing the magnet");
  set_magnet(true, [this] { transition("re_resolve"); });
}

void AttachRobotToLoadSkill::re_resolve() {
  ctx().progress(0.55, "re-resolving the grasp frame");
  // Re-checked right before the robot goes near the load.
  check_crane(params().at("check_crane").get<bool>(), [this] {
    resolve_in_robot_frame(params().at("grasp").get<std::string>(), [this](const Eigen::Isometry3d& grasp) {
      const double moved_m = (grasp.translation() - grasp_.translation()).norm();
      const double max_sway_m = params().at("max_sway_m").get<double>();
      if (moved_m > max_sway_m) {
        fail("LOAD_MOVING",
             "the grasp frame moved " + mm(moved_m) + " since planning (max_sway_m " + mm(max_sway_m) + ")");
        return;
      }
      if (auto error = check_straight_approach(approach_, grasp, params().at("max_reach_m").get<double>(),
                                               kMaxApproachLengthM, kMaxApproachAngleRad)) {
        fail("PLAN_FAILED", "re-planned approach: " + *error);
        return;
      }
      grasp_ = grasp;
      transition("approach");
    });
  });
}

void AttachRobotToLoadSkill::approach() {
  ctx().progress(0.6, "approaching the grasp frame");
  watch_crane(params().at("check_crane").get<bool>());
  const Eigen::Isometry3d pressed_in = along_tool_z(grasp_, params().at("press_in_m").get<double>());
  move_tool(pressed_in, speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] { transition("await_hold"); });
}

void AttachRobotToLoadSkill::await_hold() {
  ctx().progress(0.8, "waiting for the magnet to hold");
  wait_for_hold(params().at("hold_timeout_s").get<double>(), " of reaching the grasp frame",
                [this] { transition("verify"); });
}

void AttachRobotToLoadSkill::verify() {
  ctx().progress(0.9, "verifying the hold");
  const double verify_s = params().at("verify_s").get<double>();
  // A sample without the hold within verify_s is a loss; none is what we want (then confirm with a fresh one).
  wait_gripper([](const GripperSnapshot& g) { return !g.holding || !g.energized; }, from_seconds(verify_s),
               [this](const GripperSnapshot& g) {
                 fail("GRASP_LOST", std::string("the magnet lost the load while verifying the hold (energized=") +
                                        (g.energized ? "true" : "false") + ")");
               },
               [this] { transition("confirm"); });
}

void AttachRobotToLoadSkill::confirm() {
  // The verify window passed without a loss; a fresh sample proves the state stream is alive.
  read_gripper([this](const GripperSnapshot& g) {
    if (!g.holding || !g.energized) {
      fail("GRASP_LOST", "the magnet no longer holds the load");
      return;
    }
    succeed("the magnet holds " + params().at("object").get<std::string>() + " (verified for " +
            number_text(params().at("verify_s").get<double>()) + " s)");
  });
}

}  // namespace rigger::skill_executor
