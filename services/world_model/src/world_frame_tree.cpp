#include "world_frame_tree.hpp"

#include <algorithm>
#include <utility>

namespace rigger::world {
namespace {

struct ChainTransform {
  Eigen::Isometry3d pose_ancestor_entity = Eigen::Isometry3d::Identity();
  std::optional<Stamp> oldest_stamp;
  bool all_localized = true;
  bool any_stale = false;
};

// Composes the poses from path[0] up to (not including) path[end]: T_path[end]_path[0].
QueryResult<ChainTransform> compose_up(const EntityMap& entities, const std::vector<std::string>& path, std::size_t end) {
  ChainTransform chain;
  for (std::size_t i = 0; i < end; ++i) {
    const Entity& entity = entities.find(path[i])->second;
    if (!entity.pose) {
      return QueryResult<ChainTransform>::failure(QueryStatus::kPoseUnknown,
                                                  "entity \"" + entity.id + "\" has no pose in \"" + entity.parent + "\" yet");
    }
    chain.pose_ancestor_entity = entity.pose->pose_parent_entity * chain.pose_ancestor_entity;
    chain.oldest_stamp = chain.oldest_stamp ? std::min(*chain.oldest_stamp, entity.pose->stamp) : entity.pose->stamp;
    chain.all_localized = chain.all_localized && entity.localized;
    chain.any_stale = chain.any_stale || entity.stale;
  }
  return QueryResult<ChainTransform>::success(chain);
}

}  // namespace

std::string_view to_code(QueryStatus status) {
  switch (status) {
    case QueryStatus::kOk:
      return "OK";
    case QueryStatus::kUnknownEntity:
      return "UNKNOWN_ENTITY";
    case QueryStatus::kPoseUnknown:
      return "POSE_UNKNOWN";
    case QueryStatus::kNoCommonAncestor:
      return "NO_COMMON_ANCESTOR";
    case QueryStatus::kFrameCycle:
      return "FRAME_CYCLE";
    case QueryStatus::kUnknownFeature:
      return "UNKNOWN_FEATURE";
  }
  return "UNKNOWN";
}

QueryResult<std::vector<std::string>> path_to_root(const EntityMap& entities, std::string_view entity_id) {
  using Result = QueryResult<std::vector<std::string>>;
  std::vector<std::string> path;
  std::string_view current = entity_id;
  while (true) {
    const auto it = entities.find(current);
    if (it == entities.end()) {
      const std::string why = path.empty() ? "no entity \"" + std::string(entity_id) + "\""
                                           : "entity \"" + path.back() + "\" has an unknown parent \"" + std::string(current) + "\"";
      return Result::failure(QueryStatus::kUnknownEntity, why);
    }
    path.push_back(it->first);
    // A tree path visits each entity at most once; a longer walk means the parent links loop.
    if (path.size() > entities.size()) {
      return Result::failure(QueryStatus::kFrameCycle, "the parents of \"" + std::string(entity_id) + "\" form a cycle");
    }
    if (it->second.parent.empty()) return Result::success(std::move(path));
    current = it->second.parent;
  }
}

QueryResult<RelativePose> pose_in_frame(const EntityMap& entities, std::string_view entity_id, std::string_view frame_id) {
  using Result = QueryResult<RelativePose>;
  const auto entity_path = path_to_root(entities, entity_id);
  if (!entity_path.ok()) return Result::failure(entity_path.status, entity_path.message);
  const auto frame_path = path_to_root(entities, frame_id);
  if (!frame_path.ok()) return Result::failure(frame_path.status, frame_path.message);

  // Lowest common ancestor: the first entry of the entity's path that is also on the frame's path.
  std::size_t entity_end = 0;
  std::size_t frame_end = 0;
  bool found = false;
  for (; entity_end < entity_path.value.size() && !found; ++entity_end) {
    const auto it = std::find(frame_path.value.begin(), frame_path.value.end(), entity_path.value[entity_end]);
    if (it != frame_path.value.end()) {
      frame_end = static_cast<std::size_t>(it - frame_path.value.begin());
      found = true;
    }
  }
  if (!found) {
    return Result::failure(QueryStatus::kNoCommonAncestor, "\"" + std::string(entity_id) + "\" (root \"" +
                                                               entity_path.value.back() + "\") and \"" + std::string(frame_id) +
                                                               "\" (root \"" + frame_path.value.back() + "\") share no frame");
  }
  --entity_end;  // the loop stepped past the ancestor

  const auto up_entity = compose_up(entities, entity_path.value, entity_end);
  if (!up_entity.ok()) return Result::failure(up_entity.status, up_entity.message);
  const auto up_frame = compose_up(entities, frame_path.value, frame_end);
  if (!up_frame.ok()) return Result::failure(up_frame.status, up_frame.message);

  RelativePose result;
  result.pose_frame_entity = up_frame.value.pose_ancestor_entity.inverse() * up_entity.value.pose_ancestor_entity;
  result.oldest_stamp = up_entity.value.oldest_stamp;
  if (up_frame.value.oldest_stamp) {
    result.oldest_stamp = result.oldest_stamp ? std::min(*result.oldest_stamp, *up_frame.value.oldest_stamp)
                                              : up_frame.value.oldest_stamp;
  }
  result.all_localized = up_entity.value.all_localized && up_frame.value.all_localized;
  result.any_stale = up_entity.value.any_stale || up_frame.value.any_stale;
  return Result::success(result);
}

bool is_self_or_ancestor(const EntityMap& entities, std::string_view ancestor_id, std::string_view entity_id) {
  const auto path = path_to_root(entities, entity_id);
  if (!path.ok()) return false;
  return std::find(path.value.begin(), path.value.end(), ancestor_id) != path.value.end();
}

}  // namespace rigger::world
