#include "world_queries.hpp"

#include <cstdio>

namespace rigger::world {
namespace {

std::string seconds(std::chrono::nanoseconds d) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3f s", std::chrono::duration<double>(d).count());
  return buffer;
}

}  // namespace

std::string_view to_code(LocalizationState state) {
  switch (state) {
    case LocalizationState::kLocalized:
      return "LOCALIZED";
    case LocalizationState::kNotLocalized:
      return "NOT_LOCALIZED";
    case LocalizationState::kStale:
      return "STALE";
    case LocalizationState::kTooOld:
      return "TOO_OLD";
    case LocalizationState::kNoPose:
      return "NO_POSE";
  }
  return "UNKNOWN";
}

QueryResult<RelativePose> pose_of(const WorldStore& store, std::string_view entity_id, std::string_view frame_id) {
  return pose_in_frame(store.entities(), entity_id, frame_id);
}

QueryResult<Localization> is_localized(const WorldStore& store, std::string_view entity_id,
                                       std::optional<std::chrono::nanoseconds> max_age, Stamp now) {
  using Result = QueryResult<Localization>;
  const Entity* entity = store.find(entity_id);
  if (entity == nullptr) return Result::failure(QueryStatus::kUnknownEntity, "no entity \"" + std::string(entity_id) + "\"");
  const std::string name = "\"" + entity->id + "\"";
  Localization answer;
  if (!entity->pose) {
    answer.state = LocalizationState::kNoPose;
    answer.message = name + " has no pose";
    return Result::success(answer);
  }
  // A stamp ahead of `now` (clocks of two hosts) counts as fresh rather than as a negative age.
  answer.age = std::max(std::chrono::nanoseconds(0),
                        std::chrono::duration_cast<std::chrono::nanoseconds>(now - entity->pose->stamp));
  if (entity->stale) {
    answer.state = LocalizationState::kStale;
    answer.message = name + " was restored after a restart and has not been observed since";
  } else if (!entity->localized) {
    answer.state = LocalizationState::kNotLocalized;
    answer.message = name + " is not localized";
  } else if (max_age && *answer.age > *max_age) {
    answer.state = LocalizationState::kTooOld;
    answer.message = name + " was localized " + seconds(*answer.age) + " ago, more than the " + seconds(*max_age) + " allowed";
  } else {
    answer.localized = true;
    answer.state = LocalizationState::kLocalized;
    answer.message = name + " is localized (pose " + seconds(*answer.age) + " old, from " + entity->pose->source + ")";
  }
  return Result::success(answer);
}

QueryResult<CadFeatures> features_of(const WorldStore& store, std::string_view entity_id) {
  const Entity* entity = store.find(entity_id);
  if (entity == nullptr) {
    return QueryResult<CadFeatures>::failure(QueryStatus::kUnknownEntity, "no entity \"" + std::string(entity_id) + "\"");
  }
  return QueryResult<CadFeatures>::success(entity->features);
}

QueryResult<RelativePose> feature_pose_of(const WorldStore& store, std::string_view entity_id, std::string_view feature_id,
                                          std::string_view frame_id) {
  using Result = QueryResult<RelativePose>;
  const Entity* entity = store.find(entity_id);
  if (entity == nullptr) return Result::failure(QueryStatus::kUnknownEntity, "no entity \"" + std::string(entity_id) + "\"");
  const auto pose_entity_feature = entity->features.find_pose(feature_id);
  if (!pose_entity_feature) {
    return Result::failure(QueryStatus::kUnknownFeature,
                           "entity \"" + entity->id + "\" has no feature \"" + std::string(feature_id) + "\"");
  }
  auto result = pose_in_frame(store.entities(), entity_id, frame_id);
  if (result.ok()) result.value.pose_frame_entity = result.value.pose_frame_entity * *pose_entity_feature;
  return result;
}

std::vector<std::string> list_entities(const WorldStore& store, std::optional<EntityKind> kind) {
  std::vector<std::string> ids;
  for (const auto& [id, entity] : store.entities()) {
    if (!kind || entity.kind == *kind) ids.push_back(id);
  }
  return ids;
}

}  // namespace rigger::world
