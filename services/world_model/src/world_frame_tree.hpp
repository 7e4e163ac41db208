#pragma once
/// @file
/// The frame tree: every entity's pose is given in its parent's frame; the pose of A in B is composed
/// through their lowest common ancestor. Pure functions over an EntityMap.

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "world_types.hpp"

namespace rigger::world {

/// Outcome of a query. The code strings (to_code) are what replies carry on the wire.
enum class QueryStatus {
  kOk,                ///< "OK"
  kUnknownEntity,     ///< "UNKNOWN_ENTITY": no entity or frame with that id
  kPoseUnknown,       ///< "POSE_UNKNOWN": an entity on the path has no pose yet
  kNoCommonAncestor,  ///< "NO_COMMON_ANCESTOR": the two are in different trees
  kFrameCycle,        ///< "FRAME_CYCLE": the parent links loop (cannot happen in a WorldStore)
  kUnknownFeature,    ///< "UNKNOWN_FEATURE": the entity has no feature with that id
};

/// The wire code of a status, e.g. "POSE_UNKNOWN".
std::string_view to_code(QueryStatus status);

/// A query's value or why there is none. `value` is meaningful only when ok().
template <typename T>
struct QueryResult {
  QueryStatus status = QueryStatus::kOk;
  std::string message;  ///< human-readable reason when not ok
  T value{};

  /// True when `value` holds the answer.
  bool ok() const { return status == QueryStatus::kOk; }
  /// An answer.
  static QueryResult success(T v) { return QueryResult{QueryStatus::kOk, {}, std::move(v)}; }
  /// No answer, and why.
  static QueryResult failure(QueryStatus s, std::string why) { return QueryResult{s, std::move(why), T{}}; }
};

/// The pose of an entity expressed in another frame, with what it rests on.
struct RelativePose {
  Eigen::Isometry3d pose_frame_entity = Eigen::Isometry3d::Identity();  ///< T_frame_entity
  std::optional<Stamp> oldest_stamp;  ///< oldest pose stamp on the path; nullopt when no pose is involved
  bool all_localized = true;          ///< every pose on the path is localized
  bool any_stale = false;             ///< some pose on the path was restored after a restart
};

/// The ids from `entity_id` up to its root, both included.
/// Fails with kUnknownEntity (the entity or a parent on the way is unknown) or kFrameCycle.
QueryResult<std::vector<std::string>> path_to_root(const EntityMap& entities, std::string_view entity_id);

/// The pose of `entity_id` in the frame of `frame_id` (T_frame_entity), composed through the lowest
/// common ancestor. Fails with kUnknownEntity, kPoseUnknown (naming the entity without a pose),
/// kNoCommonAncestor or kFrameCycle.
QueryResult<RelativePose> pose_in_frame(const EntityMap& entities, std::string_view entity_id, std::string_view frame_id);

/// True when `ancestor_id` is `entity_id` itself or one of its ancestors: re-parenting `ancestor_id`
/// under `entity_id` would then close a cycle. False for unknown ids.
bool is_self_or_ancestor(const EntityMap& entities, std::string_view ancestor_id, std::string_view entity_id);

}  // namespace rigger::world
