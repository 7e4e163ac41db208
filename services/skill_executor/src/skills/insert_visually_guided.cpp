#include "insert_visually_guided.hpp"

#include <cmath>

#include "rigger/skill_sdk/pose_param.hpp"
#include "rigger/skill_sdk/states.hpp"
#include "rigger/base/text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

std::optional<std::string> insertion_goal(const nlohmann::json& features, const std::string& target,
                                          const Eigen::Vector3d& standoff_in_target_m, Eigen::Isometry3d& goal) {
  const auto insertion = features.find("insertion");
  if (insertion == features.end() || !insertion->is_object()) return std::string("it has no insertion feature");
  const std::string insertion_target = insertion->value("target", std::string());
  if (insertion_target != target) {
    return "its insertion feature is for target '" + insertion_target + "', not '" + target + "'";
  }
  if (!insertion->contains("pose_in_target")) return std::string("its insertion feature has no pose_in_target");
  try {
    goal = pose_from_param(insertion->at("pose_in_target"), target).pose;
  } catch (const std::exception& e) {
    return std::string("insertion.pose_in_target: ") + e.what();
  }
  if (!goal.matrix().allFinite()) return std::string("insertion.pose_in_target is not finite");
  goal.translation() += standoff_in_target_m;
  return std::nullopt;
}

const skill::SkillDescription& InsertVisuallyGuidedSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "InsertVisuallyGuided";
    d.kind = skill::SkillKind::kSkill;
    d.description =
        "Brings the crane-carried load held by the robot to its insertion pose on the target by visual "
        "servoing (admittance ROBOT_AND_CRANE, reference VISUAL_SERVO, tracker continuous); succeeds when "
        "converged within tolerance for settle_s, then admittance OFF (robot and crane hold, magnet on).";
    d.params = {
        params::object("object", "The tracked object that moves (held by the robot, carried by the crane).", "load"),
        params::object("target", "The tracked object it is inserted into.", "target"),
        params::number("tolerance_m").unit("m").range(0.0005, 0.05).fallback(0.005).doc(
            "Largest position error counted as inserted."),
        params::number("tolerance_rad").unit("rad").range(0.0008, 0.2).fallback(M_PI / 180.0).doc(
            "Largest rotation error counted as inserted; default 1 deg (write {\"value\": 1, \"unit\": \"deg\"})."),
        params::number("settle_s").unit("s").range(0.0, 30.0).fallback(1.0).doc(
            "The error must stay within tolerance this long."),
        params::number("timeout_s").unit("s").range(1.0, 600.0).fallback(120.0).doc(
            "Fails with TIMEOUT when not settled this long after the servo started."),
        params::number("standoff_x_m").unit("m").range(-0.5, 0.5).fallback(0.0).doc(
            "Stand-off added to the insertion position, x in the target frame."),
        params::number("standoff_y_m").unit("m").range(-0.5, 0.5).fallback(0.0).doc(
            "Stand-off added to the insertion position, y in the target frame."),
        params::number("standoff_z_m").unit("m").range(-0.5, 0.5).fallback(0.0).doc(
            "Stand-off added to the insertion position, z in the target frame (e.g. 0.05 to stop above)."),
        params::number("min_quality").range(0.0, 1.0).fallback(0.5).doc(
            "Tracker poses below this quality count as not tracked."),
        params::number("tracking_lost_s").unit("s").range(0.05, 10.0).fallback(1.0).doc(
            "Fails with TRACKING_LOST when object or target is not tracked (or the servo stops for tracking) for "
            "this long."),
    };
    d.resources = {"robot", "crane", "camera", "$object", "$target"};
    d.preconditions = {*skill::parse_predicate("attached(robot,$object)"),
                       *skill::parse_predicate("localized($object)"), *skill::parse_predicate("localized($target)")};
    d.postconditions = {*skill::parse_predicate("inserted($object,$target)")};
    d.pausable = true;
    return d;
  }();
  return kDescription;
}

InsertVisuallyGuidedSkill::InsertVisuallyGuidedSkill() {
  const auto stop = [this](SafeStopDone done) { safe_stop(done); };
  add_state({"check_crane", [this] { check_crane(); }, nothing_to_stop});
  add_state({"lookup", [this] { lookup(); }, nothing_to_stop});
  add_state({"crane_external", [this] { crane_external(); }, nothing_to_stop});
  add_state({"track", [this] { start_tracking(); }, [this](SafeStopDone done) { stop_tracking(done); }});
  // Paused, admittance goes OFF (robot and crane at rest, magnet on) while the tracker keeps tracking;
  // resumed, the servo is engaged again from where the load is (timeout_s afresh).
  const auto hold_still = [this](SafeStopDone done) {
    admittance_safe_stop(ctx().devices().admittance, nullptr, {}, done);
  };
  add_state({"engage", [this] { engage(); }, stop, hold_still, "engage"});
  add_state({"servo", [this] { servo(); }, stop, hold_still, "engage"});
  add_state({"hold", [this] { hold(); }, stop});
}

void InsertVisuallyGuidedSkill::safe_stop(const SafeStopDone& done) {
  admittance_safe_stop(ctx().devices().admittance, ctx().devices().tracker, {object_, target_}, done);
}

void InsertVisuallyGuidedSkill::stop_tracking(const SafeStopDone& done) {
  for (const std::string& id : {object_, target_}) ctx().devices().tracker->command(TrackerRequest::kStop, id);
  done(true, "tracker stopped; nothing else was commanded");
}

bool InsertVisuallyGuidedSkill::good(const TrackedObjectSample& s) const {
  return s.tracked && s.quality >= min_quality_ && s.pose.matrix().allFinite();
}

void InsertVisuallyGuidedSkill::rearm(std::uint64_t& slot, std::chrono::nanoseconds delay,
                                      std::function<void()> handler) {
  if (slot != 0) ctx().cancel_timer(slot);
  slot = ctx().after(delay, guard(std::move(handler)));
}

void InsertVisuallyGuidedSkill::cancel_timers() {
  for (std::uint64_t* slot : {&lost_timer_[0], &lost_timer_[1], &servo_stop_timer_, &settle_timer_}) {
    if (*slot != 0) ctx().cancel_timer(*slot);
    *slot = 0;
  }
}

void InsertVisuallyGuidedSkill::check_crane() {
  const Devices& devices = ctx().devices();
  if (!require_devices({{devices.admittance != nullptr, "an admittance controller"},
                        {devices.crane != nullptr, "a crane monitor"},
                        {devices.tracker != nullptr, "a vision tracker"},
                        {devices.world_access != nullptr, "a world model"}}))
    return;
  object_ = params().at("object").get<std::string>();
  target_ = params().at("target").get<std::string>();
  min_quality_ = params().at("min_quality").get<double>();
  if (object_ == target_) {
    fail("BAD_PARAMS", "/params/target: the target must differ from the object '" + object_ + "'");
    return;
  }
  ctx().progress(0.02, "checking the crane");
  check_crane_health([this] { transition("lookup"); });
}

void InsertVisuallyGuidedSkill::lookup() {
  WorldAccess* world = ctx().devices().world_access;
  const OpId id = world->features(object_, kWorldTimeout, guard([this](const OpResult& r, const nlohmann::json& f) {
                                    if (!r.ok) {
                                      fail(r.code, "features of '" + object_ + "': " + r.message);
                                      return;
                                    }
                                    const Eigen::Vector3d standoff(params().at("standoff_x_m").get<double>(),
                                                                   params().at("standoff_y_m").get<double>(),
                                                                   params().at("standoff_z_m").get<double>());
                                    if (auto error = insertion_goal(f, target_, standoff, goal_)) {
                                      fail("UNKNOWN_FEATURE", "'" + object_ + "': " + *error);
                                      return;
                                    }
                                    transition("crane_external");
                                  }));
  track([world, id] { world->cancel(id); });
}

void InsertVisuallyGuidedSkill::crane_external() {
  request_crane_external([this] { transition("track"); });
}

void InsertVisuallyGuidedSkill::start_tracking() {
  ctx().progress(0.05, "tracking " + object_ + " and " + target_);
  VisionTracker* tracker = ctx().devices().tracker;
  seen_[0] = seen_[1] = false;
  const std::string names[2] = {object_, target_};
  for (int i = 0; i < 2; ++i) {
    const OpId w = tracker->watch(names[i], guard([this, i](const TrackedObjectSample& s) {
                                    if (!good(s)) return;
                                    seen_[i] = true;
                                    if (seen_[0] && seen_[1]) transition("engage");
                                  }));
    track([tracker, w] { tracker->cancel(w); });
  }
  tracker->command(TrackerRequest::kContinuous, object_);
  tracker->command(TrackerRequest::kContinuous, target_);
  after(kTrackStartTimeout, [this] {
    fail("TRACKING_LOST", std::string("no good tracker pose of ") +
                              (!seen_[0] && !seen_[1] ? object_ + " and " + target_
                               : !seen_[0]            ? object_
                                                      : target_) +
                              " within " + std::to_string(kTrackStartTimeout.count()) + " s of TRACK_CONTINUOUS");
  });
}

void InsertVisuallyGuidedSkill::engage() {
  ctx().progress(0.1, "admittance ROBOT_AND_CRANE, visual servo to " + target_);
  AdmittanceRequest request;
  request.mode = AdmittanceModeRequest::kRobotAndCrane;
  request.reference = AdmittanceReference::kVisualServo;
  request.servo_object = object_;
  request.servo_target = target_;
  request.servo_goal_in_target = goal_;
  engage_admittance(request, "the visual servo", [this] { transition("servo"); });
}

void InsertVisuallyGuidedSkill::servo() {
  const Devices& devices = ctx().devices();
  track([this] { cancel_timers(); });

  watch_crane_health();
  // The servo's stops for lack of tracking are judged here (tracking_lost_s), not as admittance faults.
  watch_admittance(
      AdmittanceModeRequest::kRobotAndCrane, AdmittanceReference::kVisualServo,
      [this](const AdmittanceSnapshot& s) { on_admittance(s); }, is_tracking_stop_code);

  VisionTracker* tracker = devices.tracker;
  const double lost_s = params().at("tracking_lost_s").get<double>();
  const std::string names[2] = {object_, target_};
  for (int i = 0; i < 2; ++i) {
    const OpId w = tracker->watch(names[i], guard([this, i](const TrackedObjectSample& s) { on_pose(i, s); }));
    track([tracker, w] { tracker->cancel(w); });
    const std::string name = names[i];
    rearm(lost_timer_[i], from_seconds(lost_s), [this, name, lost_s] {
      fail("TRACKING_LOST", "no good tracker pose of " + name + " for " + number_text(lost_s) + " s");
    });
  }
  const double timeout_s = params().at("timeout_s").get<double>();
  after(from_seconds(timeout_s), [this, timeout_s] {
    fail("TIMEOUT",
         "not inserted within " + std::to_string(static_cast<int>(timeout_s)) + " s" +
             (last_error_m_ >= 0.0 ? "; last servo error " + servo_error_text(last_error_m_, last_error_rad_) : ""));
  });
}

void InsertVisuallyGuidedSkill::on_pose(int index, const TrackedObjectSample& s) {
  if (!good(s)) return;  // the lost timer keeps running
  const double lost_s = params().at("tracking_lost_s").get<double>();
  const std::string name = index == 0 ? object_ : target_;
  rearm(lost_timer_[index], from_seconds(lost_s), [this, name, lost_s] {
    fail("TRACKING_LOST", "no good tracker pose of " + name + " for " + number_text(lost_s) + " s");
  });
}

void InsertVisuallyGuidedSkill::on_admittance(const AdmittanceSnapshot& s) {
  if (is_tracking_stop_code(s.fault_code)) {
    // The servo stopped its reference for lack of tracking: output zero, safe. Fail only if it lasts.
    if (servo_stop_timer_ == 0) {
      const double lost_s = params().at("tracking_lost_s").get<double>();
      const std::string code = s.fault_code;
      rearm(servo_stop_timer_, from_seconds(lost_s), [this, code, lost_s] {
        fail("TRACKING_LOST", "the visual servo reported " + code + " for " + number_text(lost_s) + " s");
      });
    }
  } else {
    if (servo_stop_timer_ != 0) ctx().cancel_timer(servo_stop_timer_);
    servo_stop_timer_ = 0;
  }
  last_error_m_ = s.servo_error_m;
  last_error_rad_ = s.servo_error_rad;
  if (!last_progress_ || s.stamp - *last_progress_ >= std::chrono::seconds(1)) {
    last_progress_ = s.stamp;
    ctx().progress(-1.0, "servo error " + servo_error_text(s.servo_error_m, s.servo_error_rad));
  }
  const bool within = !s.fault && s.servo_converged && s.servo_error_m <= params().at("tolerance_m").get<double>() &&
                      s.servo_error_rad <= params().at("tolerance_rad").get<double>();
  if (!within) {
    if (settle_timer_ != 0) ctx().cancel_timer(settle_timer_);
    settle_timer_ = 0;
    return;
  }
  if (settle_timer_ == 0) {
    rearm(settle_timer_, from_seconds(params().at("settle_s").get<double>()), [this] { transition("hold"); });
  }
}

void InsertVisuallyGuidedSkill::hold() {
  ctx().progress(0.95, "inserted; admittance OFF (robot and crane hold, magnet on)");
  // Both were tracked for the servo: a target tracked by its model costs the tracker a search per image.
  for (const std::string& id : {object_, target_}) ctx().devices().tracker->command(TrackerRequest::kStop, id);
  disengage_admittance([this] {
    succeed("inserted " + object_ + " into " + target_ + " (servo error " +
            servo_error_text(last_error_m_, last_error_rad_) + "); admittance OFF, robot and crane hold, magnet on");
  });
}

}  // namespace rigger::skill_executor
