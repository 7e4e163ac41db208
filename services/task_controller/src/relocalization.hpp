#pragma once
/// @file
/// Resume after a crash, the world's half (pure): before the operator is asked, which completed
/// localizations the rest of the task relies on, and whether the world model still agrees with them
/// (docs/behavior-tree.md "Resume after a crash", step 3).
///
///  - A *localizing leaf* is a Skill or Condition whose description has the postcondition
///    `localized(X)` (Localize, ObjectLocalized). When one succeeds the controller reads X's pose in
///    `world` from the world model and journals it: kind WORLD, code LOCALIZED, the leaf's node id,
///    the pose as JSON (localized_pose_row / localized_pose_from_row).
///  - At a resume, an object X is re-checked when a localizing leaf of X is done (it, or a done
///    ancestor on a path of successes, is restored as done) and a leaf that will still run (rerun, ask,
///    pending) uses X: a precondition names it, or a string parameter is X or "X/…" (a feature of X).
///  - The check compares the world model's pose of X now with the journaled one: moved more than the
///    tolerance, a pose older than the object's max age (the smallest `max_age_s` of the recipe's
///    ObjectLocalized(X) conditions, else the configured one), not localized, no answer from the world
///    model, or no pose journaled → X's localizing leaves run again (ResumePlan::relocalize). Carried
///    objects are the exception to the displacement rule: when a done skill after the localization
///    established `attached(…, X)` (AttachRobotToLoad, Pick) and none undid it, X moved with the robot
///    by the task's own doing, and its localization stays done (the pose age still counts).
///  - A pose is only evidence if it was observed after the controller stopped: the tracker is idle
///    unless a skill asks it, so the world model's pose of a load nobody looked at since is the one the
///    localization journaled, wherever the load is now. A pose observed no later than the crashed
///    controller's last journal row is `unconfirmed`, and the localization runs again.

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "journal.hpp"
#include "resume_plan.hpp"
#include "rigger/bt/tree_spec.hpp"
#include "rigger/skill/skill_library.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::task_controller {

/// The frame localized poses are journaled and compared in.
inline constexpr const char* kRecheckFrame = "world";
/// Journal row kind and codes of a localization's pose.
inline constexpr const char* kWorldRow = "WORLD";
inline constexpr const char* kLocalizedCode = "LOCALIZED";
/// The world model did not give the pose when the localization completed (message: its code and why).
inline constexpr const char* kPoseUnknownCode = "POSE_UNKNOWN";

/// An object's pose as journaled when a localizing leaf succeeded.
struct LocalizedPose {
  std::string object;
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();  ///< in kRecheckFrame, m
  double stamp_s = 0;  ///< when the pose was observed, s since the Unix epoch
};

/// The row's message: {"object", "frame", "position_m", "quaternion_xyzw", "stamp_s"}.
std::string localized_pose_row(const LocalizedPose& pose);
/// The pose of a WORLD LOCALIZED row; nullopt for any other row or a message that does not parse.
std::optional<LocalizedPose> localized_pose_from_row(const JournalRecord& row);

/// Node id → object of every localizing leaf of `spec` (see the file comment).
std::map<std::string, std::string> localizing_leaves(const bt::TreeSpec& spec, const skill::SkillLibrary& library);

/// Tolerances of the re-check (controller configuration: resume_tolerance_mm, resume_tolerance_deg,
/// resume_max_pose_age_s).
struct RecheckSettings {
  double tolerance_m = 0.010;
  double tolerance_deg = 2.0;
  double max_age_s = 300.0;  ///< when no ObjectLocalized condition of the recipe gives one
};

/// What the resume found out about one object the rest of the task uses.
struct ObjectRecheck {
  std::string object;
  std::vector<std::string> localized_by;  ///< done localizing leaves of the object (they run again if needed)
  std::vector<std::string> used_by;       ///< leaves still to run that use it
  std::string carried_by;                 ///< a done skill that attached it after the localization, or ""
  std::optional<LocalizedPose> recorded;  ///< the latest journaled pose of those localizations
  double max_age_s = 0;
  /// The crashed controller's last journal row of the task (s since the Unix epoch; 0: unknown). A pose
  /// observed no later than this is no evidence of where the object is now.
  double interrupted_at_s = 0;
  /// When the world model was asked (wall clock, s; set by the caller; 0: the rule above is not applied).
  double checked_at_s = 0;

  // Set by judge():
  /// The world model's answer about the object now (WorldClient::pose in kRecheckFrame: `pose` is
  /// T_world_object).
  std::optional<world_client::Reply> now;
  /// "unchanged", "moved", "carried", "stale", "not_localized" (no pose, or marked so), "unrecorded" (no
  /// pose journaled at the localization), "unconfirmed" (not observed since the controller stopped),
  /// "unknown" (the world model did not answer)
  std::string verdict;
  double displacement_m = 0;
  double rotation_deg = 0;
  bool relocalize = false;          ///< its localizing leaves run again
  bool preconditions_hold = false;  ///< localized, fresh and where it was localized (or carried) now
  std::string reason;               ///< in plain words, for the prompt
};

/// The objects to re-check before the operator is asked, from the plan and the journal of the crash.
std::vector<ObjectRecheck> objects_to_recheck(const bt::TreeSpec& spec, const ResumePlan& plan,
                                              const std::vector<JournalRecord>& timeline,
                                              const skill::SkillLibrary& library, const RecheckSettings& settings);

/// Judges `check` against the world model's answer `now` (ok=false: it did not answer, or not with a
/// pose: the safe side, the localization runs again); `spec` names the nodes in the reason.
void judge(ObjectRecheck& check, const world_client::Reply& now, const RecheckSettings& settings,
           const bt::TreeSpec& spec);

/// The localizing leaves to run again (plan_resume's `again`).
std::set<std::string> leaves_to_relocalize(const std::vector<ObjectRecheck>& checks);

/// details_json's "world": one object per check (object, verdict, relocalize, preconditions_hold,
/// localized, pose_age_s, max_age_s, displacement_mm, rotation_deg, localized_at, localized_by, used_by,
/// carried_by, world_model, reason).
nlohmann::json to_json(const std::vector<ObjectRecheck>& checks);
/// One line per object: "world: <reason>".
std::string describe_checks(const std::vector<ObjectRecheck>& checks);

}  // namespace rigger::task_controller
