#include "gripper_skill.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

std::string mm(double m) { return std::to_string(static_cast<long long>(std::lround(m * 1000.0))) + " mm"; }

double speed_scale_for(double tool_speed_mps) {
  return std::clamp(tool_speed_mps / kRobotMaxToolSpeedMps, 0.001, 1.0);
}

skill::SkillDescription gripper_skill_description(std::string name, std::string description,
                                                  std::vector<skill::ParamSpec> params,
                                                  const std::vector<std::string>& preconditions,
                                                  const std::vector<std::string>& postconditions) {
  skill::SkillDescription d;
  d.name = std::move(name);
  d.kind = skill::SkillKind::kSkill;
  d.description = std::move(description);
  d.params = std::move(params);
  d.resources = {"robot", "gripper", "$object"};
  d.pausable = true;
  const auto parse = [&d](const std::string& text) {
    std::string error;
    auto predicate = skill::parse_predicate(text, &error);
    if (!predicate) throw std::logic_error(d.name + ": predicate '" + text + "': " + error);
    return *predicate;
  };
  for (const auto& text : preconditions) d.preconditions.push_back(parse(text));
  for (const auto& text : postconditions) d.postconditions.push_back(parse(text));
  return d;
}

skill::ParamSpec max_reach_param() {
  return params::number("max_reach_m").unit("m").range(0.1, 5.0).fallback(1.2).doc(
      "Tool poses farther than this from the robot base are refused by the planner.");
}
skill::ParamSpec timeout_param() {
  return params::number("timeout_s").unit("s").range(1.0, 600.0).fallback(60.0).doc(
      "The whole skill; TIMEOUT (after the current state's safe stop) when it takes longer.");
}

Eigen::Isometry3d along_tool_z(const Eigen::Isometry3d& pose, double distance_m) {
  return pose * Eigen::Translation3d(0.0, 0.0, distance_m);
}

std::optional<std::string> check_straight_approach(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to,
                                                   double max_reach_m, double max_length_m, double max_angle_rad) {
  for (const auto* pose : {&from, &to}) {
    PoseParam p{*pose, kRobotBaseFrame};
    if (auto error = plan_cartesian_goal(p, max_reach_m)) return *error;
  }
  const double length_m = (to.translation() - from.translation()).norm();
  if (length_m > max_length_m)
    return "the straight approach is " + mm(length_m) + " long, more than the " + mm(max_length_m) + " allowed";
  const double angle_rad = Eigen::AngleAxisd(from.linear().transpose() * to.linear()).angle();
  if (angle_rad > max_angle_rad) {
    return "the approach and grasp orientations differ by " + std::to_string(angle_rad * 180.0 / M_PI) +
           " deg (a straight approach allows " + std::to_string(max_angle_rad * 180.0 / M_PI) + " deg)";
  }
  return std::nullopt;
}

GripperSkill::~GripperSkill() {
  if (overall_timer_ != 0) ctx().cancel_timer(overall_timer_);
}

void GripperSkill::add_motion_state(std::string name, std::function<void()> on_enter) {
  const auto stop = [this](SafeStopDone done) { stop_robot(done); };
  add_state({std::move(name), std::move(on_enter), stop, stop});
}

bool GripperSkill::require_devices(bool robot, bool gripper, bool world) {
  const Devices& d = ctx().devices();
  return Skill::require_devices({{!robot || d.robot != nullptr, "robot"},
                                 {!gripper || d.gripper != nullptr, "gripper"},
                                 {!world || d.world != nullptr, "world model"}});
}

void GripperSkill::start_overall_timeout(double timeout_s) {
  overall_timeout_ = from_seconds(timeout_s);
  overall_timeout_s_ = timeout_s;
  arm_overall_timeout();
}

void GripperSkill::arm_overall_timeout() {
  // Not a state timer: it spans every state. fail() runs the current state's safe stop first.
  overall_timer_ = ctx().after(overall_timeout_, [this] {
    overall_timer_ = 0;
    if (finished() || stopping()) return;
    fail("TIMEOUT",
         "not done within timeout_s = " + number_text(overall_timeout_s_) + " s (in state " + state() + ")");
  });
}

void GripperSkill::on_run_paused() {
  if (overall_timer_ == 0) return;
  ctx().cancel_timer(overall_timer_);
  overall_timer_ = 0;
  overall_held_ = true;
}

void GripperSkill::on_run_resumed() {
  if (!overall_held_) return;
  overall_held_ = false;
  arm_overall_timeout();
}

void GripperSkill::check_crane(bool required, std::function<void()> then) {
  if (!required) {
    then();
    return;
  }
  if (ctx().devices().crane == nullptr) {
    fail("DEVICE_UNAVAILABLE", "this executor has no crane state (needed by check_crane = true)");
    return;
  }
  check_crane_health(std::move(then), std::chrono::nanoseconds::zero());
}

void GripperSkill::watch_crane(bool required) {
  if (required) watch_crane_health(std::chrono::seconds(1));  // check_crane() refused a missing crane before
}

void GripperSkill::resolve_in_robot_frame(const std::string& ref, std::function<void(const Eigen::Isometry3d&)> then) {
  FeatureResolver* world = ctx().devices().world;
  const OpId id = world->resolve(
      ref, kRobotBaseFrame, kResolveTimeout,
      guard([this, ref, then = std::move(then)](const OpResult& result, const ResolvedFeature& feature) {
        if (!result.ok) {
          fail(result.code.empty() ? "WORLD_UNREACHABLE" : result.code, "feature " + ref + ": " + result.message);
          return;
        }
        if (!feature.localized) {
          fail("NOT_LOCALIZED", "feature " + ref + ": its entity has not been localized (run Localize first)");
          return;
        }
        if (feature.frame != kRobotBaseFrame) {
          fail("NOT_VERIFIABLE",
               "feature " + ref + " came back in frame '" + feature.frame + "', not '" + kRobotBaseFrame + "'");
          return;
        }
        then(feature.pose);
      }));
  if (id != 0) track([world, id] { world->cancel(id); });
}

void GripperSkill::move_tool(const Eigen::Isometry3d& pose_robot_tool, double speed_scale,
                             std::chrono::nanoseconds timeout, std::function<void()> then) {
  MotionGoal goal;
  goal.kind = MotionGoal::Kind::kCartesian;
  goal.pose_frame_tool = pose_robot_tool;
  goal.frame = kRobotBaseFrame;
  goal.speed_scale = speed_scale;
  RobotMotion* robot = ctx().devices().robot;
  const OpId id = robot->move(goal, timeout, guard([this, then = std::move(then)](const OpResult& result) {
                                if (result.ok)
                                  then();
                                else
                                  fail(result.code.empty() ? "MOTION_FAILED" : result.code, result.message);
                              }));
  track([robot, id] { robot->cancel(id); });
}

void GripperSkill::set_magnet(bool energize, std::function<void()> then) {
  Gripper* gripper = ctx().devices().gripper;
  const OpId id = gripper->set_energized(
      energize, kGripperTimeout, guard([this, energize, then = std::move(then)](const OpResult& result) {
        if (result.ok)
          then();
        else
          fail("GRIPPER_TIMEOUT", std::string("the gripper did not confirm ") + (energize ? "energize" : "release") +
                                      ": " + result.message);
      }));
  track([gripper, id] { gripper->cancel(id); });
}

void GripperSkill::wait_gripper(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                                std::function<void(const GripperSnapshot&)> on_sample,
                                std::function<void()> on_timeout) {
  Gripper* gripper = ctx().devices().gripper;
  const OpId id = gripper->wait_state(
      std::move(predicate), timeout,
      guard([on_sample = std::move(on_sample), on_timeout = std::move(on_timeout)](std::optional<GripperSnapshot> s) {
        if (s)
          on_sample(*s);
        else
          on_timeout();
      }));
  track([gripper, id] { gripper->cancel(id); });
}

void GripperSkill::wait_released(std::function<void()> then) {
  wait_gripper([](const GripperSnapshot& g) { return !g.energized && !g.holding; }, kGripperTimeout,
               [then = std::move(then)](const GripperSnapshot&) { then(); },
               [this] {
                 fail("RELEASE_FAILED", "the gripper still reports energized or holding " +
                                            std::to_string(kGripperTimeout.count()) + " s after the release");
               });
}

void GripperSkill::wait_for_hold(double timeout_s, const std::string& since, std::function<void()> then) {
  wait_gripper([](const GripperSnapshot& g) { return g.holding; }, from_seconds(timeout_s),
               [then = std::move(then)](const GripperSnapshot&) { then(); },
               [this, timeout_s, since] {
                 fail("GRASP_FAILED",
                      "the magnet did not report holding within " + number_text(timeout_s) + " s" + since);
               });
}

void GripperSkill::read_gripper(std::function<void(const GripperSnapshot&)> then) {
  wait_gripper([](const GripperSnapshot&) { return true; }, kStateTimeout, std::move(then),
               [this] {
                 fail("GRIPPER_STATE_STALE",
                      "no rigger/gripper/state sample within " + std::to_string(kStateTimeout.count()) + " s");
               });
}

void GripperSkill::read_robot(std::function<void(const RobotSnapshot&)> then) {
  RobotMotion* robot = ctx().devices().robot;
  const OpId id = robot->next_state(
      kStateTimeout, guard([this, then = std::move(then)](std::optional<RobotSnapshot> s) {
        if (!s) {
          fail("ROBOT_STATE_STALE",
               "no rigger/robot/state sample within " + std::to_string(kStateTimeout.count()) + " s");
          return;
        }
        if (s->frame != kRobotBaseFrame) {
          fail("NOT_VERIFIABLE", "the robot reports its tool in '" + s->frame + "', not '" + kRobotBaseFrame + "'");
          return;
        }
        if (!s->fault.empty()) {
          fail("ROBOT_FAULT", "the robot reports the fault '" + s->fault + "'");
          return;
        }
        then(*s);
      }));
  track([robot, id] { robot->cancel(id); });
}

void GripperSkill::stop_robot(const SafeStopDone& done) {
  // Not guarded: the safe stop runs after the state was left, and its answer is what STOPPED waits for.
  ctx().devices().robot->stop(kStopTimeout, [done](const OpResult& result) { done(result.ok, result.message); });
}

}  // namespace rigger::skill_executor
