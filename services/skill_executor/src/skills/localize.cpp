#include "localize.hpp"

#include "fixed_text.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

const skill::SkillDescription& LocalizeSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "Localize";
    d.kind = skill::SkillKind::kSkill;
    d.description =
        "Detects an object with the camera (rigger/tracker/command TRACK_ONCE, or TRACK_ONCE_MODEL without "
        "markers; rigger/tracker/pose) and stores its pose, quality and localized=true in the world model "
        "(rigger/world/update, accepted).";
    d.params = {
        params::object("object", "World-model id of the object to localize (the tracker's object_id)."),
        params::choice("method", {"markers", "model"}).fallback("markers").doc(
            "`markers`: the object's ArUco markers in the grey image. `model`: no markers; the object's STEP "
            "model searched for in the depth image, from its pose in the world model; a pose is taken only when "
            "it fits, otherwise the skill fails with the tracker's code (NOT_FOUND, LOW_FIT, AMBIGUOUS, "
            "BAD_DEPTH, NO_VISIBLE_SURFACE, NO_DEPTH) when the time is up, or NO_MODEL at once."),
        params::number("min_quality").range(0.0, 1.0).fallback(0.5).doc("Lowest accepted tracking quality."),
        params::number("timeout_s").unit("s").range(0.1, 60.0).fallback(5.0).doc(
            "Fails with NOT_DETECTED when no good enough pose arrived within this time."),
    };
    d.resources = {"camera"};
    d.postconditions = {*skill::parse_predicate("localized($object)")};
    return d;
  }();
  return kDescription;
}

LocalizeSkill::LocalizeSkill() {
  add_state({"detect", [this] { detect(); }, nothing_to_stop});
  add_state({"update", [this] { update(); }, nothing_to_stop});
}

void LocalizeSkill::detect() {
  const Devices& devices = ctx().devices();
  if (devices.tracker == nullptr || devices.world_access == nullptr) {
    fail("DEVICE_UNAVAILABLE",
         devices.tracker == nullptr ? "this executor has no vision tracker" : "this executor has no world model");
    return;
  }
  object_ = params().at("object").get<std::string>();
  min_quality_ = params().at("min_quality").get<double>();
  by_model_ = params().at("method").get<std::string>() == "model";
  ctx().progress(0.1, "detecting " + object_);
  VisionTracker* tracker = devices.tracker;
  const OpId watch = tracker->watch(object_, guard([this](const TrackedObjectSample& s) { on_sample(s); }));
  track([tracker, watch] { tracker->cancel(watch); });
  track([this] {
    if (retry_timer_ != 0) ctx().cancel_timer(retry_timer_);
    retry_timer_ = 0;
  });
  send_once();
  const double timeout_s = params().at("timeout_s").get<double>();
  after(from_seconds(timeout_s), [this, timeout_s] {
    if (by_model_ && last_seen_ && !last_seen_->status.empty() && last_seen_->status != "FOUND") {
      fail(last_seen_->status, "no pose of '" + object_ + "' fitted its model within " + fixed(timeout_s, 1) +
                                   " s: " + last_seen_->status + ": " + last_seen_->detail);
      return;
    }
    std::string seen = "no pose of it arrived";
    if (last_seen_) {
      seen = !last_seen_->tracked
                 ? "the last pose said not tracked"
                 : "the last pose had quality " + fixed(last_seen_->quality, 2) + " < " + fixed(min_quality_, 2);
    }
    fail("NOT_DETECTED", "no good pose of '" + object_ + "' within " + fixed(timeout_s, 1) + " s: " + seen);
  });
}

void LocalizeSkill::send_once() {
  last_command_ =
      ctx().devices().tracker->command(by_model_ ? TrackerRequest::kOnceByModel : TrackerRequest::kOnce, object_);
  if (!first_command_) first_command_ = last_command_;
  // Re-armed per command: a pose lost on the best-effort topic must not stall the detection.
  if (retry_timer_ != 0) ctx().cancel_timer(retry_timer_);
  retry_timer_ = ctx().after(by_model_ ? kModelRetryPeriod : kRetryPeriod, guard([this] {
                               retry_timer_ = 0;
                               send_once();
                             }));
}

void LocalizeSkill::on_sample(const TrackedObjectSample& s) {
  if (s.stamp <= *first_command_) return;  // an image taken before we asked
  last_seen_ = s;
  if (s.tracked && s.quality >= min_quality_ && s.pose.matrix().allFinite()) {
    detected_ = s;
    transition("update");
    return;
  }
  if (by_model_ && s.status == "NO_MODEL") {  // asking again cannot help
    fail("NO_MODEL", "cannot localize '" + object_ + "' by its model: " + s.detail);
    return;
  }
  // The tracker looked at an image after our last command and went idle: ask again at once.
  if (s.stamp > last_command_) send_once();
}

void LocalizeSkill::update() {
  ++update_attempts_;
  ctx().progress(0.7, "storing the pose of " + object_ + " (quality " + fixed(detected_->quality, 2) + ")");
  WorldAccess* world = ctx().devices().world_access;
  const TrackedObjectSample s = *detected_;
  const OpId id = world->update_pose(
      object_, s.frame, s.pose, s.stamp, s.quality, kUpdateTimeout, guard([this, s](const OpResult& result) {
        if (result.ok) {
          succeed("localized " + object_ + " in '" + s.frame + "' at (" + fixed(s.pose.translation().x(), 3) + ", " +
                  fixed(s.pose.translation().y(), 3) + ", " + fixed(s.pose.translation().z(), 3) + ") m, quality " +
                  fixed(s.quality, 2));
          return;
        }
        if (result.code == "STAMP_BACKWARDS" && update_attempts_ < kMaxUpdateAttempts) {
          ctx().log()->info("Localize {}: the world model holds a newer pose ({}); detecting again", object_,
                            result.message);
          first_command_.reset();
          transition("detect");
          return;
        }
        if (result.code == "WORLD_UNREACHABLE")
          fail("WORLD_UNREACHABLE", result.message);
        else
          fail("WORLD_UPDATE_REJECTED",
               "the world model rejected the pose of " + object_ + ": " + result.code + ": " + result.message);
      }));
  track([world, id] { world->cancel(id); });
}

}  // namespace rigger::skill_executor
