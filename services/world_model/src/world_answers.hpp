#pragma once
/// @file
/// Answers to decoded queries: what the world model puts in a `rigger/world/reply`, as a domain value
/// (the node converts it to the wire). Pure function of the store and `now`.

#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "wire_decoding.hpp"
#include "world_queries.hpp"

namespace rigger::world {

/// The answer to one query. On ok=false, `code` and `message` say why.
struct QueryAnswer {
  bool ok = false;
  std::string code;     ///< "OK"; is-localized: the LocalizationState code; errors: the QueryStatus code
  std::string message;
  Eigen::Isometry3d pose_frame_entity = Eigen::Isometry3d::Identity();  ///< kPose: T_frame_entity (or feature)
  std::string frame;    ///< kPose: the frame of `pose_frame_entity`
  Stamp stamp{};        ///< kPose: oldest stamp on the path; kIsLocalized: the pose's stamp (epoch when none)
  bool localized = false;  ///< kPose: every pose on the path localized and none stale; kIsLocalized: the answer
  double age_s = 0.0;      ///< age of `stamp` at `now`, s (0 when none or in the future)
  nlohmann::json result;   ///< kFeatures: features; kEntity: the entity; kList: ids; kPose: path details
};

/// Answers `query` from `store` at `now`. Never throws.
QueryAnswer answer_query(const WorldStore& store, const WorldQuery& query, Stamp now);

}  // namespace rigger::world
