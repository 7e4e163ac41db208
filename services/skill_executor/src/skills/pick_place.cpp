#include "pick_place.hpp"

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

namespace {

skill::ParamSpec approach_m_param() {
  return params::number("approach_m").unit("m").range(0.01, kPickPlaceMaxApproachM).fallback(0.10).doc(
      "The approach pose is the target tool pose moved back this far along the tool's -z axis.");
}
skill::ParamSpec approach_speed_param() {
  return params::number("approach_speed_m_per_s").unit("m/s").range(0.005, 0.25).fallback(0.05).doc(
      "Tool speed of the straight descent and of the retreat.");
}
skill::ParamSpec retreat_param() {
  return params::number("retreat_m").unit("m").range(0.0, kPickPlaceMaxApproachM).fallback(0.10).doc(
      "Straight retreat along the tool's -z axis at the end (0: none).");
}
skill::ParamSpec speed_scale_param() {
  return params::number("speed_scale").range(0.01, 1.0).fallback(0.2).doc(
      "Fraction of the robot's maximum speed for the transfer to the approach pose.");
}

/// Plans the straight descent onto `target` (a tool pose in the robot base frame) from the approach pose,
/// approach_m back along the tool's -z axis, and the straight retreat of retreat_m from it: sets
/// `approach`, returns the planner's error or std::nullopt.
std::optional<std::string> plan_descent_and_retreat(const nlohmann::json& params, const Eigen::Isometry3d& target,
                                                    Eigen::Isometry3d& approach) {
  approach = along_tool_z(target, -params.at("approach_m").get<double>());
  const double reach_m = params.at("max_reach_m").get<double>();
  if (auto error = check_straight_approach(approach, target, reach_m, kPickPlaceMaxApproachM, 1e-6)) return error;
  return check_straight_approach(along_tool_z(target, -params.at("retreat_m").get<double>()), target, reach_m,
                                 kPickPlaceMaxApproachM, 1e-6);
}
}  // namespace

// ---- Pick ---------------------------------------------------------------------------------------

const skill::SkillDescription& PickSkill::describe() {
  static const skill::SkillDescription kDescription = gripper_skill_description(
      "Pick",
      "Picks an object within the robot's payload with the magnetic gripper: approach pose, straight "
      "descent to the grasp frame, energize and confirm the hold, straight retreat.",
      {
        params::object("object", "The object picked (claimed while the skill runs)."),
        params::feature("grasp").doc("Grasp frame = tool pose at the grasp (z into the object), e.g. part/grasp_top."),
        approach_m_param(),
        approach_speed_param(),
        retreat_param(),
        speed_scale_param(),
        params::number("hold_timeout_s").unit("s").range(0.1, 10.0).fallback(2.0).doc(
            "After energizing, the magnet must report holding within this time (else GRASP_FAILED)."),
        max_reach_param(),
        timeout_param(),
      },
      {"localized($object)"}, {"attached(robot,$object)"});
  return kDescription;
}

PickSkill::PickSkill() {
  add_state({"check", [this] { check(); }, nothing_to_stop});
  add_state({"resolve", [this] { resolve(); }, nothing_to_stop});
  add_motion_state("move_approach", [this] { move_approach(); });
  add_motion_state("descend", [this] { descend(); });
  add_state({"grip", [this] { grip(); }, nothing_to_stop});
  add_state({"await_hold", [this] { await_hold(); }, nothing_to_stop});
  add_motion_state("retreat", [this] { retreat(); });
  add_state({"verify", [this] { verify(); }, nothing_to_stop});
}

void PickSkill::check() {
  if (!require_devices(true, true, true)) return;
  start_overall_timeout(params().at("timeout_s").get<double>());
  ctx().progress(0.0, "checking the gripper");
  read_gripper([this](const GripperSnapshot& g) {
    if (g.holding) {
      fail("GRIPPER_OCCUPIED", "the gripper already holds something");
      return;
    }
    transition("resolve");
  });
}

void PickSkill::resolve() {
  resolve_in_robot_frame(params().at("grasp").get<std::string>(), [this](const Eigen::Isometry3d& grasp) {
    grasp_ = grasp;
    if (auto error = plan_descent_and_retreat(params(), grasp_, approach_)) {
      fail("PLAN_FAILED", *error);
      return;
    }
    transition("move_approach");
  });
}

void PickSkill::move_approach() {
  ctx().progress(0.2, "moving to the approach pose");
  move_tool(approach_, params().at("speed_scale").get<double>(), motion_timeout(), [this] { transition("descend"); });
}

void PickSkill::descend() {
  ctx().progress(0.4, "descending to the grasp");
  move_tool(grasp_, speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] { transition("grip"); });
}

void PickSkill::grip() {
  ctx().progress(0.6, "energizing the magnet");
  set_magnet(true, [this] { transition("await_hold"); });
}

void PickSkill::await_hold() {
  wait_for_hold(params().at("hold_timeout_s").get<double>(), "", [this] {
    transition(params().at("retreat_m").get<double>() <= 0.0 ? "verify" : "retreat");
  });
}

void PickSkill::retreat() {
  ctx().progress(0.8, "retreating with the object");
  move_tool(along_tool_z(grasp_, -params().at("retreat_m").get<double>()),
            speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] { transition("verify"); });
}

void PickSkill::verify() {
  read_gripper([this](const GripperSnapshot& g) {
    if (!g.holding) {
      fail("GRASP_LOST", "the object was lost during the retreat");
      return;
    }
    succeed("picked " + params().at("object").get<std::string>());
  });
}

// ---- Place --------------------------------------------------------------------------------------

const skill::SkillDescription& PlaceSkill::describe() {
  static const skill::SkillDescription kDescription = gripper_skill_description(
      "Place",
      "Places a held object: approach pose, straight descent to the place pose, release and confirm, "
      "straight retreat; then the world model is told the object is no longer localized (Localize it again "
      "before anything needs its pose).",
      {
        params::object("object", "The object placed (claimed while the skill runs)."),
        params::pose("pose").doc(
            "Tool pose at the release (z into the support), in the robot base frame \"robot\" (the default) or "
            "relative to a world-model feature named as its frame, e.g. \"frame\": \"fixture/place_top\"."),
        approach_m_param(),
        approach_speed_param(),
        retreat_param(),
        speed_scale_param(),
        max_reach_param(),
        timeout_param(),
      },
      {"attached(robot,$object)"}, {"!attached(robot,$object)", "placed($object)", "!localized($object)"});
  return kDescription;
}

PlaceSkill::PlaceSkill() {
  add_state({"check", [this] { check(); }, nothing_to_stop});
  add_state({"resolve", [this] { resolve(); }, nothing_to_stop});
  add_motion_state("move_approach", [this] { move_approach(); });
  add_motion_state("descend", [this] { descend(); });
  add_state({"release", [this] { release(); }, nothing_to_stop});
  add_state({"confirm_released", [this] { confirm_released(); }, nothing_to_stop});
  add_motion_state("retreat", [this] { retreat(); });
}

void PlaceSkill::check() {
  pose_ = pose_from_param(params().at("pose"), kRobotBaseFrame);
  const bool feature_frame = split_feature_ref(pose_.frame).has_value();
  if (!require_devices(true, true, feature_frame)) return;
  if (!feature_frame && pose_.frame != kRobotBaseFrame) {
    fail("PLAN_FAILED", "the place pose is in frame '" + pose_.frame + "'; Place takes the robot base frame '" +
                            kRobotBaseFrame + "' or a world-model feature (entity/feature)");
    return;
  }
  start_overall_timeout(params().at("timeout_s").get<double>());
  ctx().progress(0.0, "checking the gripper");
  read_gripper([this](const GripperSnapshot& g) {
    if (!g.holding) {
      fail("NOT_HOLDING", "the gripper holds nothing to place");
      return;
    }
    transition("resolve");
  });
}

void PlaceSkill::resolve() {
  if (pose_.frame == kRobotBaseFrame) {
    planned(pose_.pose);
    return;
  }
  resolve_in_robot_frame(pose_.frame, [this](const Eigen::Isometry3d& feature) { planned(feature * pose_.pose); });
}

void PlaceSkill::planned(const Eigen::Isometry3d& place) {
  place_ = place;
  if (auto error = plan_descent_and_retreat(params(), place_, approach_)) {
    fail("PLAN_FAILED", *error);
    return;
  }
  transition("move_approach");
}

void PlaceSkill::move_approach() {
  ctx().progress(0.2, "moving to the approach pose");
  move_tool(approach_, params().at("speed_scale").get<double>(), motion_timeout(), [this] { transition("descend"); });
}

void PlaceSkill::descend() {
  ctx().progress(0.4, "descending to the place pose");
  move_tool(place_, speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] { transition("release"); });
}

void PlaceSkill::release() {
  ctx().progress(0.6, "releasing");
  set_magnet(false, [this] { transition("confirm_released"); });
}

void PlaceSkill::confirm_released() {
  wait_released([this] {
    if (params().at("retreat_m").get<double>() <= 0.0)
      succeed_unlocalizing(params().at("object").get<std::string>(), "placed (no retreat)");
    else
      transition("retreat");
  });
}

void PlaceSkill::retreat() {
  ctx().progress(0.8, "retreating");
  move_tool(along_tool_z(place_, -params().at("retreat_m").get<double>()),
            speed_scale_for(params().at("approach_speed_m_per_s").get<double>()), motion_timeout(),
            [this] {
              const std::string object = params().at("object").get<std::string>();
              succeed_unlocalizing(object, "placed " + object);
            });
}

}  // namespace rigger::skill_executor
