#include "move_to.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

#include <cmath>

namespace rigger::skill_executor {

std::optional<std::string> plan_cartesian_goal(const PoseParam& goal, double max_reach_m) {
  // Planning and verification happen in the robot base frame, the frame of rigger/robot/state; a goal
  // in another frame would need the world model's transform, which MoveTo does not query.
  if (goal.frame != kRobotBaseFrame)
    return "the goal is in frame '" + goal.frame + "'; MoveTo plans in the robot base frame '" + kRobotBaseFrame + "'";
  if (!goal.pose.matrix().allFinite()) return "the goal pose has a non-finite value";
  const double reach_m = goal.pose.translation().norm();
  if (reach_m > max_reach_m) {
    return "the goal is " + number_text(reach_m) + " m from the robot base, beyond the reach of " +
           number_text(max_reach_m) + " m";
  }
  return std::nullopt;
}

const skill::SkillDescription& MoveToSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "MoveTo";
    d.kind = skill::SkillKind::kSkill;
    d.description = "Moves the robot's tool to a Cartesian goal pose (planned, executed via rigger/robot/cmd_motion, "
                    "verified against rigger/robot/state).";
    d.params = {
        params::pose("goal").doc("Tool goal pose in the robot base frame \"robot\" (the default frame)."),
        params::speed_scale(0.2),
        params::number("timeout_s").unit("s").range(0.1, 600.0).fallback(30.0).doc(
            "The motion fails with TIMEOUT (and is stopped) when it takes longer."),
        params::number("position_tolerance_m").unit("m").range(0.0001, 0.1).fallback(0.005).doc(
            "Largest distance between the reached and the goal position."),
        params::number("max_reach_m").unit("m").range(0.1, 5.0).fallback(1.2).doc(
            "Goals farther than this from the robot base are refused by the planner."),
    };
    d.resources = {"robot"};
    d.pausable = true;
    return d;
  }();
  return kDescription;
}

MoveToSkill::MoveToSkill() {
  add_state({"plan", [this] { plan(); }, nothing_to_stop});
  // Paused, the arm stops where it is; resumed, the motion is planned again from there (timeout_s afresh).
  const auto stop = [this](SafeStopDone done) { stop_robot(done); };
  add_state({"move", [this] { move(); }, stop, stop});
  add_state({"verify", [this] { verify(); }, nothing_to_stop});
}

void MoveToSkill::plan() {
  if (ctx().devices().robot == nullptr) {
    fail("DEVICE_UNAVAILABLE", "this executor has no robot");
    return;
  }
  goal_ = pose_from_param(params().at("goal"), kRobotBaseFrame);
  if (auto error = plan_cartesian_goal(goal_, params().at("max_reach_m").get<double>())) {
    fail("PLAN_FAILED", *error);
    return;
  }
  transition("move");
}

void MoveToSkill::move() {
  ctx().progress(0.1, "moving");
  MotionGoal goal;
  goal.kind = MotionGoal::Kind::kCartesian;
  goal.pose_frame_tool = goal_.pose;
  goal.frame = goal_.frame;
  goal.speed_scale = params().at("speed_scale").get<double>();
  RobotMotion* robot = ctx().devices().robot;
  const OpId id = robot->move(goal, from_seconds(params().at("timeout_s").get<double>()),
                              guard([this](const OpResult& result) {
                                if (result.ok) transition("verify");
                                else fail(result.code, result.message);
                              }));
  track([robot, id] { robot->cancel(id); });
}

void MoveToSkill::verify() {
  ctx().progress(0.9, "verifying");
  RobotMotion* robot = ctx().devices().robot;
  const OpId id = robot->next_state(kStateTimeout, guard([this](std::optional<RobotSnapshot> state) {
    if (!state) {
      fail("ROBOT_STATE_STALE", "no robot state within " + std::to_string(kStateTimeout.count()) + " s");
      return;
    }
    if (state->frame != goal_.frame) {
      fail("NOT_VERIFIABLE", "the robot reports its tool in '" + state->frame + "', the goal is in '" + goal_.frame + "'");
      return;
    }
    const double error_m = (state->tool_pose.translation() - goal_.pose.translation()).norm();
    const double tolerance_m = params().at("position_tolerance_m").get<double>();
    if (error_m > tolerance_m) {
      fail("NOT_AT_GOAL", "the tool is " + std::to_string(error_m * 1000.0) + " mm from the goal (tolerance " +
                              std::to_string(tolerance_m * 1000.0) + " mm)");
      return;
    }
    succeed("at goal within " + std::to_string(error_m * 1000.0) + " mm");
  }));
  track([robot, id] { robot->cancel(id); });
}

void MoveToSkill::stop_robot(const SafeStopDone& done) {
  // Not guarded: the safe stop runs after the state was left, and its answer is what STOPPED waits for.
  ctx().devices().robot->stop(kStopTimeout, [done](const OpResult& result) { done(result.ok, result.message); });
}

}  // namespace rigger::skill_executor
