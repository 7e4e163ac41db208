#pragma once
/// @file
/// The authoritative entity store: built from the cell configuration, changed only by validated
/// updates. An update is applied entirely or not at all; a rejected update leaves the store unchanged
/// and says why. Every accepted update yields a ChangeRecord (who, what, when, the state after).
///
/// Thread safety: none; one thread (the world model's work loop) owns a WorldStore.

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "world_cell_config.hpp"
#include "world_types.hpp"

namespace rigger::world {

/// A pose as it arrives on the wire: position and a quaternion that has yet to be checked.
struct PoseValue {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< must be unit within kUnitQuaternionTolerance
};

/// A proposed change of one entity. Absent fields are left as they are.
struct EntityUpdate {
  std::string entity_id;
  std::string source;   ///< who proposes it (process, tracker or skill id); required
  Stamp stamp{};        ///< when the information was observed; required (> the Unix epoch)
  std::optional<std::string> parent;  ///< re-parent; needs `pose` (the pose in the new parent)
  std::optional<PoseValue> pose;      ///< pose in the (new) parent frame
  std::optional<Covariance6d> covariance;  ///< replaces the pose's covariance; needs `pose`
  std::optional<double> quality;      ///< replaces the pose's quality, in [0, 1]; needs `pose`
  std::optional<bool> localized;      ///< default: true when `pose` is given, else unchanged
  std::optional<nlohmann::json> attributes_patch;  ///< RFC 7396 merge patch on the attributes object
};

/// Why an update was rejected (or kAccepted). to_code gives the wire string.
enum class UpdateStatus {
  kAccepted,             ///< "ACCEPTED"
  kUnknownEntity,        ///< "UNKNOWN_ENTITY"
  kMissingSource,        ///< "MISSING_SOURCE": empty source
  kMissingStamp,         ///< "MISSING_STAMP": stamp at or before the Unix epoch
  kStampBackwards,       ///< "STAMP_BACKWARDS": older than the entity's last accepted change
  kEmptyUpdate,          ///< "EMPTY_UPDATE": nothing to change
  kRootFrame,            ///< "ROOT_FRAME": a root frame has no parent and no pose
  kUnknownParent,        ///< "UNKNOWN_PARENT": the new parent is not an entity
  kFrameCycle,           ///< "FRAME_CYCLE": the new parent is the entity or one of its descendants
  kParentWithoutPose,    ///< "PARENT_WITHOUT_POSE": a re-parent must give the pose in the new parent
  kNotFinite,            ///< "NOT_FINITE": NaN or infinity in the pose, covariance or attributes
  kNonUnitQuaternion,    ///< "NON_UNIT_QUATERNION"
  kBadCovariance,        ///< "BAD_COVARIANCE": not symmetric or a negative variance
  kBadQuality,           ///< "BAD_QUALITY": outside [0, 1]
  kBadAttributes,        ///< "BAD_ATTRIBUTES": the patch is not an object, or too deep
  kLocalizedWithoutPose, ///< "LOCALIZED_WITHOUT_POSE": localized=true for an entity with no pose
  kEstimateWithoutPose,  ///< "ESTIMATE_WITHOUT_POSE": covariance or quality without a pose
};

/// The wire code of a status, e.g. "STAMP_BACKWARDS".
std::string_view to_code(UpdateStatus status);

/// One part of an entity that an accepted update changed.
/// kAdded, kRemoved and kConfiguration (features, model, camera, attributes) come from cell revisions.
enum class ChangedField {
  kParent,
  kPose,
  kCovariance,
  kQuality,
  kLocalized,
  kStale,
  kAttributes,
  kAdded,
  kRemoved,
  kConfiguration
};
/// "parent", "pose", "covariance", "quality", "localized", "stale", "attributes", "added", "removed",
/// "configuration".
std::string_view to_string(ChangedField field);

/// What an accepted update did: who, what, when, and the entity's state afterwards.
struct ChangeRecord {
  std::uint64_t revision = 0;    ///< store-wide, increases by one per accepted change (continues after restart)
  std::string entity_id;
  std::string source;
  Stamp stamp{};
  std::vector<ChangedField> changed;  ///< empty when the update restated the current state
  Entity after;

  /// "pose,localized" style list of the changed fields ("none" when empty).
  std::string what() const;
};

/// The verdict on an update. `change` is set exactly when accepted.
struct UpdateResult {
  UpdateStatus status = UpdateStatus::kAccepted;
  std::string reason;  ///< human-readable, names the field; empty when accepted
  std::optional<ChangeRecord> change;

  /// True when the update was applied.
  bool accepted() const { return status == UpdateStatus::kAccepted; }
};

/// |‖q‖ − 1| above this rejects an update's quaternion.
inline constexpr double kUnitQuaternionTolerance = 1e-6;
/// Relative asymmetry of a covariance above this rejects it.
inline constexpr double kCovarianceSymmetryTolerance = 1e-9;
/// Attribute patches nested deeper than this are rejected.
inline constexpr int kMaxAttributeDepth = 16;

/// The state a WorldDatabase saved: the last state of every entity that ever changed.
struct PersistedWorld {
  std::vector<Entity> entities;  ///< dynamic state (id, kind, parent, pose, flags, stamps, source, attributes)
  std::uint64_t revision = 0;    ///< the highest revision saved (0 when nothing was)
};

/// What WorldStore::restore_stale did.
struct RestoreReport {
  std::vector<std::string> restored;  ///< entity ids restored (stale, not localized)
  std::vector<std::string> ignored;   ///< persisted ids no longer configured, or whose parent is gone
};

/// The entity store (see the file comment): configuration + validated updates.
class WorldStore {
 public:
  /// Builds the store from a validated configuration. Configuration poses are stamped `loaded_at`
  /// with source "config:<file>"; every entity's `stamp` is `loaded_at`.
  static WorldStore from_config(const CellConfig& config, Stamp loaded_at);

  /// Validates and applies an update (all or nothing). Never throws; on rejection the store is unchanged.
  UpdateResult apply(const EntityUpdate& update);

  /// Applies a cell revision (validated, CAD derived; docs/world-model.md "Cell revisions"): adds the
  /// entities it adds, removes the ones it lacks; for the `moved` ids takes parent, pose and localized
  /// from it (the person who moved it in the document says where it is); for the `changed` ids takes
  /// attributes from it; every entity takes features, model and camera from it. The other entities keep
  /// their current pose estimate. One ChangeRecord per entity added, removed, moved or changed, by
  /// `source`, stamped `now`. Never throws.
  std::vector<ChangeRecord> apply_revision(const CellConfig& next, const std::set<std::string>& moved,
                                           const std::set<std::string>& changed, Stamp now, const std::string& source);

  /// Brings back the state saved before a restart (see world_persistence.hpp). Each persisted entity
  /// still in the configuration gets its parent, pose, stamps, source and attributes back, marked
  /// stale=true and localized=false (never fresh); features, model and camera stay the configuration's.
  /// Entities that are no longer configured, or whose parent is gone or would close a cycle, are
  /// ignored. The revision counter continues after `persisted.revision`. Never throws.
  RestoreReport restore_stale(const PersistedWorld& persisted);

  /// The entity with this id, or nullptr.
  const Entity* find(std::string_view id) const;
  /// All entities by id.
  const EntityMap& entities() const { return entities_; }
  /// The revision of the last accepted change (0 before any).
  std::uint64_t revision() const { return revision_; }

 private:
  EntityMap entities_;
  std::uint64_t revision_ = 0;
};

}  // namespace rigger::world
