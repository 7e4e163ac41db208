#pragma once
/// @file
/// Queries on a WorldStore: pure functions of the store's state and, where age matters, of a `now`
/// supplied by the caller (the world model has no clock of its own in its logic).

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "world_frame_tree.hpp"
#include "world_store.hpp"

namespace rigger::world {

/// Why an entity is or is not localized.
enum class LocalizationState {
  kLocalized,     ///< "LOCALIZED": localized and (if a max age was asked) young enough
  kNotLocalized,  ///< "NOT_LOCALIZED": the localized flag is false
  kStale,         ///< "STALE": restored after a restart, not observed since
  kTooOld,        ///< "TOO_OLD": localized, but the pose is older than the max age
  kNoPose,        ///< "NO_POSE": the entity has no pose at all
};

/// The wire code, e.g. "TOO_OLD".
std::string_view to_code(LocalizationState state);

/// The answer to "is X localized (with a pose no older than max_age)?".
struct Localization {
  bool localized = false;
  LocalizationState state = LocalizationState::kNoPose;
  std::optional<std::chrono::nanoseconds> age;  ///< now − pose stamp (0 when the stamp is in the future)
  std::string message;                          ///< a sentence saying why
};

/// The pose of `entity_id` in `frame_id` through the frame tree (see pose_in_frame).
QueryResult<RelativePose> pose_of(const WorldStore& store, std::string_view entity_id, std::string_view frame_id);

/// Whether `entity_id` is localized; with `max_age`, also whether its pose is at most that old at
/// `now`. Configuration poses are stamped with the load time, so ask calibrated devices without a max
/// age. Fails only with kUnknownEntity.
QueryResult<Localization> is_localized(const WorldStore& store, std::string_view entity_id,
                                       std::optional<std::chrono::nanoseconds> max_age, Stamp now);

/// The CAD features of an entity (possibly empty). Fails with kUnknownEntity.
QueryResult<CadFeatures> features_of(const WorldStore& store, std::string_view entity_id);

/// The pose of a named feature (grasp frame, approach waypoint, screw hole, "rope_attachment") of
/// `entity_id`, expressed in `frame_id`: T_frame_feature. Fails like pose_of, or with kUnknownFeature.
QueryResult<RelativePose> feature_pose_of(const WorldStore& store, std::string_view entity_id, std::string_view feature_id,
                                          std::string_view frame_id);

/// The ids of all entities, in id order; only those of `kind` when given.
std::vector<std::string> list_entities(const WorldStore& store, std::optional<EntityKind> kind = std::nullopt);

}  // namespace rigger::world
