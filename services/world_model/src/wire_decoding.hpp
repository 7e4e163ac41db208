#pragma once
/// @file
/// The world model's wire boundary: `rigger/world/update` and `rigger/world/query` messages (read
/// from their samples by common/world_protocol's from_wire, which checks nothing) become store values
/// here, with every check a sample can fail before it reaches the store: ids of the right form,
/// strings and JSON within bounds, numbers finite, the stamp's nanoseconds below one second, the query
/// kind known. Checks that need the store's state (unknown entity or frame, stamp going backwards, a
/// non-unit quaternion, covariance shape) are the store's and the queries' (world_store.hpp,
/// world_queries.hpp); the decoder keeps the quaternion exactly as sent so that the store can reject it.
///
/// Never throws; any bytes in a wire struct give a value or a DecodeError. The overloads on a wire
/// sample read it with world_protocol::from_wire first (the tests and fuzzers feed samples).

#include <chrono>
#include <optional>
#include <string>
#include <variant>

#include <rigger/idl/types.hpp>

#include "rigger/world_protocol/world_protocol.hpp"
#include "world_store.hpp"

namespace rigger::world {

/// Why a sample was refused before reaching the store. `code` is the wire code.
struct DecodeError {
  std::string code;     ///< "BAD_ID", "BAD_STAMP", "BAD_ATTRIBUTES", "NOT_FINITE", "MISSING_SOURCE", "BAD_QUERY"
  std::string message;  ///< names the field and what was expected
};

/// A value or the reason there is none.
template <typename T>
using Decoded = std::variant<T, DecodeError>;

/// Largest accepted attributes_json (bytes).
inline constexpr std::size_t kMaxAttributesJsonBytes = 64 * 1024;

/// What a query asks (see idl/world.idl WorldQuery).
using world_protocol::QueryKind;

/// A decoded query.
struct WorldQuery {
  std::string client_id;
  std::uint64_t request_id = 0;
  QueryKind kind = QueryKind::kList;
  std::string entity_id;   ///< every kind but kList
  std::string frame_id;    ///< kPose
  std::string feature_id;  ///< kPose: empty for the entity itself
  std::optional<std::chrono::nanoseconds> max_age;  ///< kIsLocalized: absent when max_age_s <= 0
  std::optional<EntityKind> list_kind;              ///< kList: only entities of this kind
};

/// Decodes an update: entity_id and source must be identifiers, the stamp valid (nanosec < 1e9),
/// the parent frame (when non-empty) an identifier, the pose/covariance/quality finite when given,
/// attributes_json (when non-empty) a JSON object within kMaxAttributesJsonBytes and
/// kMaxAttributeDepth. Absent parts (has_* false) are absent in the result.
Decoded<EntityUpdate> decode_update(const world_protocol::Update& update);
Decoded<EntityUpdate> decode_update(const rigger_world_EntityUpdate& wire);

/// Decodes a query: a known kind; entity_id an identifier (except kList); frame_id an identifier for
/// kPose; feature_id empty or an identifier; max_age_s finite.
Decoded<WorldQuery> decode_query(const world_protocol::Query& query);
Decoded<WorldQuery> decode_query(const rigger_world_WorldQuery& wire);

/// The source name of updates that come from `rigger/tracker/pose`.
inline constexpr const char* kTrackerSource = "vision_tracker";

/// Turns a tracker sample into an update of `object_id`: when tracked, its pose in header.frame_id
/// (re-parenting when that differs; empty: the current parent), the quality, the covariance unless
/// covariance[0] < 0 or all zeros (ROS: unknown), localized=true; when lost, only localized=false.
/// Stamped with the image stamp; source kTrackerSource. Same checks as decode_update.
Decoded<EntityUpdate> decode_tracked_pose(const rigger_vision_TrackedPose& wire);

}  // namespace rigger::world
