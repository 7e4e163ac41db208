#include "world_store.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "world_frame_tree.hpp"
#include "world_json.hpp"

namespace rigger::world {
namespace {

using nlohmann::json;

UpdateResult reject(UpdateStatus status, std::string reason) { return UpdateResult{status, std::move(reason), std::nullopt}; }

std::string seconds_text(Stamp stamp) {
  const std::int64_t ns = to_unix_ns(stamp);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%lld.%09lld s", static_cast<long long>(ns / 1000000000),
                static_cast<long long>(std::llabs(ns % 1000000000)));
  return buffer;
}

// Finite numbers and bounded nesting in a JSON value; reports the first offending pointer.
UpdateStatus check_json(const json& value, const std::string& pointer, int depth, std::string& where) {
  if (depth > kMaxAttributeDepth) {
    where = pointer;
    return UpdateStatus::kBadAttributes;
  }
  if (value.is_number_float() && !std::isfinite(value.get<double>())) {
    where = pointer;
    return UpdateStatus::kNotFinite;
  }
  if (value.is_object()) {
    for (const auto& item : value.items()) {
      const UpdateStatus status = check_json(item.value(), join_pointer(pointer, item.key()), depth + 1, where);
      if (status != UpdateStatus::kAccepted) return status;
    }
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      const UpdateStatus status = check_json(value[i], pointer + "/" + std::to_string(i), depth + 1, where);
      if (status != UpdateStatus::kAccepted) return status;
    }
  }
  return UpdateStatus::kAccepted;
}

bool same_covariance(const std::optional<Covariance6d>& a, const std::optional<Covariance6d>& b) {
  if (a.has_value() != b.has_value()) return false;
  return !a || *a == *b;
}

}  // namespace

std::string_view to_code(UpdateStatus status) {
  switch (status) {
    case UpdateStatus::kAccepted:
      return "ACCEPTED";
    case UpdateStatus::kUnknownEntity:
      return "UNKNOWN_ENTITY";
    case UpdateStatus::kMissingSource:
      return "MISSING_SOURCE";
    case UpdateStatus::kMissingStamp:
      return "MISSING_STAMP";
    case UpdateStatus::kStampBackwards:
      return "STAMP_BACKWARDS";
    case UpdateStatus::kEmptyUpdate:
      return "EMPTY_UPDATE";
    case UpdateStatus::kRootFrame:
      return "ROOT_FRAME";
    case UpdateStatus::kUnknownParent:
      return "UNKNOWN_PARENT";
    case UpdateStatus::kFrameCycle:
      return "FRAME_CYCLE";
    case UpdateStatus::kParentWithoutPose:
      return "PARENT_WITHOUT_POSE";
    case UpdateStatus::kNotFinite:
      return "NOT_FINITE";
    case UpdateStatus::kNonUnitQuaternion:
      return "NON_UNIT_QUATERNION";
    case UpdateStatus::kBadCovariance:
      return "BAD_COVARIANCE";
    case UpdateStatus::kBadQuality:
      return "BAD_QUALITY";
    case UpdateStatus::kBadAttributes:
      return "BAD_ATTRIBUTES";
    case UpdateStatus::kLocalizedWithoutPose:
      return "LOCALIZED_WITHOUT_POSE";
    case UpdateStatus::kEstimateWithoutPose:
      return "ESTIMATE_WITHOUT_POSE";
  }
  return "UNKNOWN";
}

std::string_view to_string(ChangedField field) {
  switch (field) {
    case ChangedField::kParent:
      return "parent";
    case ChangedField::kPose:
      return "pose";
    case ChangedField::kCovariance:
      return "covariance";
    case ChangedField::kQuality:
      return "quality";
    case ChangedField::kLocalized:
      return "localized";
    case ChangedField::kStale:
      return "stale";
    case ChangedField::kAttributes:
      return "attributes";
    case ChangedField::kAdded:
      return "added";
    case ChangedField::kRemoved:
      return "removed";
    case ChangedField::kConfiguration:
      return "configuration";
  }
  return "unknown";
}

std::string ChangeRecord::what() const {
  if (changed.empty()) return "none";
  std::string text;
  for (const ChangedField field : changed) text += (text.empty() ? "" : ",") + std::string(to_string(field));
  return text;
}

WorldStore WorldStore::from_config(const CellConfig& config, Stamp loaded_at) {
  config.require_cad_derived("the world model");
  WorldStore store;
  const std::string source = "config:" + config.source;
  for (const cell::CellEntity& configured : config.entities) {
    Entity entity;
    entity.id = configured.id;
    entity.kind = configured.kind;
    entity.parent = configured.parent;
    if (configured.pose_parent_entity) {
      entity.pose = PoseEstimate{*configured.pose_parent_entity, loaded_at, source, std::nullopt, std::nullopt};
    }
    entity.localized = configured.localized;
    entity.stamp = loaded_at;
    entity.source = source;
    entity.features = configured.features;
    entity.model = configured.model;
    entity.camera = configured.camera;
    entity.attributes = configured.attributes;
    store.entities_.emplace(entity.id, std::move(entity));
  }
  return store;
}

UpdateResult WorldStore::apply(const EntityUpdate& update) {
  const auto it = entities_.find(update.entity_id);
  if (it == entities_.end()) return reject(UpdateStatus::kUnknownEntity, "no entity \"" + update.entity_id + "\"");
  const Entity& current = it->second;
  const std::string& id = current.id;

  if (update.source.empty()) return reject(UpdateStatus::kMissingSource, "update of \"" + id + "\": source is empty");
  if (update.stamp <= Stamp{}) {
    return reject(UpdateStatus::kMissingStamp, "update of \"" + id + "\": stamp " + seconds_text(update.stamp) +
                                                   " is not after the Unix epoch");
  }
  if (update.stamp < current.stamp) {
    return reject(UpdateStatus::kStampBackwards, "update of \"" + id + "\": stamp " + seconds_text(update.stamp) +
                                                     " is older than the last accepted change at " +
                                                     seconds_text(current.stamp));
  }
  if (!update.parent && !update.pose && !update.covariance && !update.quality && !update.localized &&
      !update.attributes_patch) {
    return reject(UpdateStatus::kEmptyUpdate, "update of \"" + id + "\" changes nothing");
  }
  if (current.parent.empty() && (update.parent || update.pose || update.covariance || update.quality || update.localized)) {
    return reject(UpdateStatus::kRootFrame,
                  "\"" + id + "\" is a root frame: it has no parent, pose or localized flag (only attributes may change)");
  }

  if (update.parent) {
    if (entities_.find(*update.parent) == entities_.end()) {
      return reject(UpdateStatus::kUnknownParent, "update of \"" + id + "\": parent \"" + *update.parent + "\" is not an entity");
    }
    if (is_self_or_ancestor(entities_, id, *update.parent)) {
      return reject(UpdateStatus::kFrameCycle, "update of \"" + id + "\": parent \"" + *update.parent +
                                                   "\" is the entity itself or one of its descendants");
    }
    if (!update.pose) {
      return reject(UpdateStatus::kParentWithoutPose,
                    "update of \"" + id + "\": a new parent needs the pose in that parent");
    }
  }

  if (update.pose) {
    if (!update.pose->position_m.allFinite()) {
      return reject(UpdateStatus::kNotFinite, "update of \"" + id + "\": pose position is not finite");
    }
    if (!update.pose->orientation.coeffs().allFinite()) {
      return reject(UpdateStatus::kNotFinite, "update of \"" + id + "\": pose orientation is not finite");
    }
    const double norm = update.pose->orientation.norm();
    if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
      return reject(UpdateStatus::kNonUnitQuaternion,
                    "update of \"" + id + "\": orientation quaternion has norm " + std::to_string(norm) + ", expected 1");
    }
  } else if (update.covariance || update.quality) {
    return reject(UpdateStatus::kEstimateWithoutPose,
                  "update of \"" + id + "\": a covariance or quality describes a pose, and none is given");
  }

  if (update.covariance) {
    const Covariance6d& c = *update.covariance;
    if (!c.allFinite()) return reject(UpdateStatus::kNotFinite, "update of \"" + id + "\": covariance is not finite");
    const double scale = std::max(1.0, c.cwiseAbs().maxCoeff());
    if ((c - c.transpose()).cwiseAbs().maxCoeff() > kCovarianceSymmetryTolerance * scale) {
      return reject(UpdateStatus::kBadCovariance, "update of \"" + id + "\": covariance is not symmetric");
    }
    if ((c.diagonal().array() < 0.0).any()) {
      return reject(UpdateStatus::kBadCovariance, "update of \"" + id + "\": covariance has a negative variance");
    }
  }
  if (update.quality) {
    if (!std::isfinite(*update.quality)) return reject(UpdateStatus::kNotFinite, "update of \"" + id + "\": quality is not finite");
    if (*update.quality < 0.0 || *update.quality > 1.0) {
      return reject(UpdateStatus::kBadQuality,
                    "update of \"" + id + "\": quality " + std::to_string(*update.quality) + " is outside [0, 1]");
    }
  }

  const bool has_pose_after = update.pose.has_value() || current.pose.has_value();
  const bool localized_after = update.localized.value_or(update.pose ? true : current.localized);
  if (localized_after && !has_pose_after) {
    return reject(UpdateStatus::kLocalizedWithoutPose, "update of \"" + id + "\": localized=true but the entity has no pose");
  }

  json attributes_after = current.attributes;
  if (update.attributes_patch) {
    if (!update.attributes_patch->is_object()) {
      return reject(UpdateStatus::kBadAttributes, "update of \"" + id + "\": attributes patch must be a JSON object, got " +
                                                      describe_json(*update.attributes_patch));
    }
    std::string where;
    const UpdateStatus status = check_json(*update.attributes_patch, "/attributes", 0, where);
    if (status == UpdateStatus::kNotFinite) {
      return reject(status, "update of \"" + id + "\": " + where + " is not a finite number");
    }
    if (status != UpdateStatus::kAccepted) {
      return reject(status, "update of \"" + id + "\": " + where + " is nested deeper than " +
                                std::to_string(kMaxAttributeDepth) + " levels");
    }
    attributes_after.merge_patch(*update.attributes_patch);
  }

  // Every check passed: build the next state, then commit it in one assignment.
  Entity next = current;
  ChangeRecord change;
  if (update.parent && *update.parent != current.parent) change.changed.push_back(ChangedField::kParent);
  if (update.parent) next.parent = *update.parent;
  if (update.pose) {
    PoseEstimate estimate;
    estimate.pose_parent_entity = Eigen::Isometry3d::Identity();
    estimate.pose_parent_entity.linear() = update.pose->orientation.normalized().toRotationMatrix();
    estimate.pose_parent_entity.translation() = update.pose->position_m;
    estimate.stamp = update.stamp;
    estimate.source = update.source;
    estimate.covariance = update.covariance;
    estimate.quality = update.quality;
    const std::optional<Covariance6d> old_covariance = current.pose ? current.pose->covariance : std::nullopt;
    // Plain values rather than std::optional comparisons: GCC 12 warns maybe-uninitialized on those.
    const bool had_quality = current.pose && current.pose->quality;
    const double old_quality = had_quality ? *current.pose->quality : 0.0;
    change.changed.push_back(ChangedField::kPose);
    if (!same_covariance(old_covariance, estimate.covariance)) change.changed.push_back(ChangedField::kCovariance);
    if (had_quality != estimate.quality.has_value() || (had_quality && old_quality != *estimate.quality)) {
      change.changed.push_back(ChangedField::kQuality);
    }
    next.pose = estimate;
  }
  if (localized_after != current.localized) change.changed.push_back(ChangedField::kLocalized);
  next.localized = localized_after;
  // A new observation (a pose or an explicit localization) supersedes what was restored after a restart.
  if (current.stale && (update.pose || update.localized.value_or(false))) {
    next.stale = false;
    change.changed.push_back(ChangedField::kStale);
  }
  if (attributes_after != current.attributes) change.changed.push_back(ChangedField::kAttributes);
  next.attributes = std::move(attributes_after);
  next.stamp = update.stamp;
  next.source = update.source;

  it->second = next;
  change.revision = ++revision_;
  change.entity_id = id;
  change.source = update.source;
  change.stamp = update.stamp;
  change.after = std::move(next);
  return UpdateResult{UpdateStatus::kAccepted, {}, std::move(change)};
}

std::vector<ChangeRecord> WorldStore::apply_revision(const CellConfig& next, const std::set<std::string>& moved,
                                                     const std::set<std::string>& changed, Stamp now,
                                                     const std::string& source) {
  WorldStore revised = from_config(next, now);  // every entity as the revision describes it
  std::vector<ChangeRecord> records;
  const auto record = [&](const Entity& after, std::vector<ChangedField> fields) {
    ChangeRecord c;
    c.revision = ++revision_;
    c.entity_id = after.id;
    c.source = source;
    c.stamp = now;
    c.changed = std::move(fields);
    c.after = after;
    records.push_back(std::move(c));
  };
  for (auto it = entities_.begin(); it != entities_.end();) {
    if (revised.entities_.count(it->first) > 0) {
      ++it;
      continue;
    }
    const Entity gone = it->second;
    it = entities_.erase(it);
    record(gone, {ChangedField::kRemoved});
  }
  for (auto& [id, configured] : revised.entities_) {
    const auto it = entities_.find(id);
    if (it == entities_.end()) {
      entities_.emplace(id, configured);
      record(configured, {ChangedField::kAdded});
      continue;
    }
    Entity& entity = it->second;
    entity.features = configured.features;
    entity.model = configured.model;
    entity.camera = configured.camera;
    std::vector<ChangedField> fields;
    if (moved.count(id) > 0) {
      if (entity.parent != configured.parent) fields.push_back(ChangedField::kParent);
      fields.push_back(ChangedField::kPose);
      entity.parent = configured.parent;
      entity.pose = configured.pose;
      entity.localized = configured.localized;
      entity.stale = false;
    }
    if (changed.count(id) > 0) {
      entity.attributes = configured.attributes;
      fields.push_back(ChangedField::kConfiguration);
    }
    if (fields.empty()) continue;
    entity.stamp = now;
    entity.source = source;
    record(entity, std::move(fields));
  }
  return records;
}

RestoreReport WorldStore::restore_stale(const PersistedWorld& persisted) {
  RestoreReport report;
  for (const Entity& restored : persisted.entities) {
    const auto it = entities_.find(restored.id);
    bool ok = it != entities_.end() && it->second.parent.empty() == restored.parent.empty();
    if (ok && !restored.parent.empty()) {
      ok = entities_.find(restored.parent) != entities_.end() &&
           (restored.parent == it->second.parent || !is_self_or_ancestor(entities_, restored.id, restored.parent));
    }
    if (!ok) {
      report.ignored.push_back(restored.id);
      continue;
    }
    Entity& entity = it->second;
    entity.parent = restored.parent;
    entity.pose = restored.pose;
    entity.stamp = restored.stamp;
    entity.source = restored.source;
    entity.attributes = restored.attributes.is_object() ? restored.attributes : json::object();
    entity.localized = false;
    entity.stale = true;
    report.restored.push_back(restored.id);
  }
  // Revisions keep increasing across restarts, so change-log rows are never reused.
  revision_ = std::max(revision_, persisted.revision);
  return report;
}

const Entity* WorldStore::find(std::string_view id) const {
  const auto it = entities_.find(id);
  return it == entities_.end() ? nullptr : &it->second;
}

}  // namespace rigger::world
