#include "nudge.hpp"

#include <string>

#include "rigger/skill_sdk/params.hpp"

namespace example {

namespace sdk = rigger::skill_sdk;
namespace params = rigger::skill_sdk::params;

const rigger::skill::SkillDescription& NudgeSkill::describe() {
  static const rigger::skill::SkillDescription kDescription = [] {
    rigger::skill::SkillDescription d;
    d.name = "Nudge";
    d.kind = rigger::skill::SkillKind::kSkill;
    d.description = "Moves the robot's tool by an offset in the robot base frame from where it is, and back.";
    d.params = {
        params::number("dx_m").unit("m").range(-0.2, 0.2).fallback(0.0).doc("Offset along the base's x."),
        params::number("dy_m").unit("m").range(-0.2, 0.2).fallback(0.0).doc("Offset along the base's y."),
        params::number("dz_m").unit("m").range(-0.2, 0.2).fallback(0.05).doc("Offset along the base's z."),
        params::boolean("return").fallback(true).doc("Move back to the start pose afterwards."),
        params::number("tolerance_m").unit("m").range(0.0005, 0.02).fallback(0.003).doc(
            "Largest distance between a reached and a commanded position."),
        params::speed_scale(0.1),
        params::timeout_s(20.0, "Each motion is stopped and the skill fails with TIMEOUT when it takes longer."),
    };
    d.resources = {"robot"};
    d.pausable = false;
    return d;
  }();
  return kDescription;
}

NudgeSkill::NudgeSkill() {
  const auto stop = [this](SafeStopDone done) { stop_robot(done); };
  add_state({"read_start", [this] { read_start(); }, sdk::nothing_to_stop});
  add_state({"nudge", [this] { move(nudged_, "verify_nudge"); }, stop});
  add_state({"verify_nudge", [this] { verify(nudged_, "back"); }, sdk::nothing_to_stop});
  add_state({"back", [this] { move(start_, "verify_back"); }, stop});
  add_state({"verify_back", [this] { verify(start_, ""); }, sdk::nothing_to_stop});
}

void NudgeSkill::read_start() {
  sdk::RobotMotion* robot = ctx().devices().robot;
  if (robot == nullptr) {
    fail("DEVICE_UNAVAILABLE", "this executor has no robot");
    return;
  }
  const sdk::OpId id = robot->next_state(std::chrono::seconds(1), guard([this](std::optional<sdk::RobotSnapshot> s) {
    if (!s) {
      fail("ROBOT_STATE_STALE", "no robot state within 1 s");
      return;
    }
    start_ = s->tool_pose;
    nudged_ = start_;
    nudged_.translation() += Eigen::Vector3d(params().at("dx_m").get<double>(), params().at("dy_m").get<double>(),
                                             params().at("dz_m").get<double>());
    transition("nudge");
  }));
  track([robot, id] { robot->cancel(id); });
}

void NudgeSkill::move(const Eigen::Isometry3d& goal, const char* then) {
  ctx().progress(std::string(then) == "verify_nudge" ? 0.2 : 0.6, std::string("moving to ") + then);
  sdk::MotionGoal motion;
  motion.kind = sdk::MotionGoal::Kind::kCartesian;
  motion.pose_frame_tool = goal;
  motion.speed_scale = params().at("speed_scale").get<double>();
  sdk::RobotMotion* robot = ctx().devices().robot;
  const auto timeout = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(params().at("timeout_s").get<double>()));
  const sdk::OpId id = robot->move(motion, timeout, guard([this, then = std::string(then)](const sdk::OpResult& r) {
    if (!r.ok) {
      fail(r.code, r.message);
      return;
    }
    transition(then);
  }));
  track([robot, id] { robot->cancel(id); });
}

void NudgeSkill::verify(const Eigen::Isometry3d& goal, const char* then) {
  sdk::RobotMotion* robot = ctx().devices().robot;
  const sdk::OpId id = robot->next_state(
      std::chrono::seconds(1), guard([this, goal, then = std::string(then)](std::optional<sdk::RobotSnapshot> s) {
        if (!s) {
          fail("ROBOT_STATE_STALE", "no robot state within 1 s");
          return;
        }
        const double error_m = (s->tool_pose.translation() - goal.translation()).norm();
        if (error_m > params().at("tolerance_m").get<double>()) {
          fail("NOT_REACHED", "the tool stopped " + std::to_string(error_m * 1000.0) + " mm from its goal");
          return;
        }
        if (then == "back" && params().at("return").get<bool>()) {
          transition("back");
        } else {
          succeed("the tool is " + std::to_string(error_m * 1000.0) + " mm from its goal");
        }
      }));
  track([robot, id] { robot->cancel(id); });
}

void NudgeSkill::stop_robot(const SafeStopDone& done) {
  ctx().devices().robot->stop(std::chrono::seconds(2), [done](const sdk::OpResult& r) { done(r.ok, r.message); });
}

}  // namespace example
