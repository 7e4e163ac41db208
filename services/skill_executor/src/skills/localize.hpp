#pragma once
/// @file
/// Localize: detects an object with the camera and stores its pose in the world model.
///
///   detect ──good pose──▶ update ──ACCEPTED──▶ SUCCESS
///     │                    │ STAMP_BACKWARDS (a newer pose landed first): back to detect, at most 3 times
///     ▼ (timeout)          ▼ (rejected / unreachable)
///   NOT_DETECTED         WORLD_UPDATE_REJECTED / WORLD_UNREACHABLE
///
/// detect: TRACK_ONCE for the object (repeated every kRetryPeriod, and at once after a pose of a newer
/// image that was not good enough, since the tracker goes idle after one image), until a
/// rigger/tracker/pose of the object with tracked=true, quality ≥ min_quality and an image stamp newer
/// than the first command. update: rigger/world/update of pose (in the tracker's frame), quality and
/// localized=true, stamped with the image's stamp; waits for the world model's accepted result, so the
/// postcondition localized(object) holds when it succeeds (the world model may also follow the tracker
/// topic by itself; the equal stamp is accepted).
///
/// method "model": TRACK_ONCE_MODEL instead (the tracker answers each with one sample from a depth
/// image: a pose that fits the object's STEP model, or tracked=false with a status code); asked again
/// after each answer and every kModelRetryPeriod until the timeout, which fails with the last answer's
/// code (NOT_FOUND, LOW_FIT, AMBIGUOUS, BAD_DEPTH, NO_VISIBLE_SURFACE, NO_DEPTH); NO_MODEL fails at once.
///
/// Safe stops: nothing moves in either state (the tracker goes idle by itself after TRACK_ONCE).
/// Params: object, method (markers | model), min_quality (0–1, default 0.5), timeout_s (0.1–60 s, default 5).
/// Claims "camera".
/// Failure codes: DEVICE_UNAVAILABLE, NOT_DETECTED, WORLD_UPDATE_REJECTED, WORLD_UNREACHABLE, and with
/// method "model" the tracker's codes above.

#include <optional>
#include <string>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

class LocalizeSkill final : public Skill {
 public:
  static const skill::SkillDescription& describe();
  LocalizeSkill();

  /// TRACK_ONCE is repeated this often while no good pose arrived (a best-effort pose may be lost).
  static constexpr std::chrono::milliseconds kRetryPeriod{500};
  /// With method "model": the tracker answers every request (at the latest after its once_timeout_s, 2 s
  /// by default), so the request is repeated without an answer only this late.
  static constexpr std::chrono::milliseconds kModelRetryPeriod{3000};
  /// How long the world model may take to answer the update.
  static constexpr std::chrono::seconds kUpdateTimeout{2};
  /// Updates refused with STAMP_BACKWARDS are retried with a fresh detection this often at most.
  static constexpr int kMaxUpdateAttempts = 3;

 private:
  void detect();
  void on_sample(const TrackedObjectSample& sample);
  void send_once();
  void update();

  std::string object_;
  double min_quality_ = 0.5;
  bool by_model_ = false;
  std::optional<WallTime> first_command_;
  WallTime last_command_;
  std::optional<TrackedObjectSample> last_seen_;
  std::optional<TrackedObjectSample> detected_;
  int update_attempts_ = 0;
  std::uint64_t retry_timer_ = 0;
};

}  // namespace rigger::skill_executor
