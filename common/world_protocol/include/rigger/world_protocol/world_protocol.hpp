#pragma once
/// @file
/// The world model's wire protocol (idl/world.idl, the `rigger/world/*` topics) in one domain form for
/// both halves: the client (common/world_client) writes queries and updates and reads replies and update
/// results; the world model (services/world_model) does the reverse and publishes entity states and
/// changes. Each message is converted here once, to_wire and from_wire, with its round-trip test;
/// nothing else fills or reads these samples' fields.
///
/// from_wire takes the sample as sent and checks nothing a wire value can carry: ids, bounds, finite
/// numbers and the quaternion's norm are the world model's to judge (services/world_model
/// wire_decoding.hpp). to_wire's strings borrow the message's: write the sample while the message lives.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include <rigger/idl/types.hpp>

#include "rigger/base/time.hpp"

namespace rigger::world_protocol {

using Covariance6d = Eigen::Matrix<double, 6, 6>;

/// What an entity is (rigger/world/entity kind; the cell file's kinds).
enum class EntityKind { kObject, kDevice, kFrame };

/// What a query asks (rigger/world/query kind).
enum class QueryKind { kPose, kIsLocalized, kFeatures, kEntity, kList };

/// rigger/world/query: a question of `client_id`, answered on rigger/world/reply with `request_id`.
struct Query {
  std::string client_id;
  std::uint64_t request_id = 0;
  /// nullopt after from_wire when the sample's kind is a value this build does not know; `wire_kind`
  /// then holds it (to say so, and to write it back).
  std::optional<QueryKind> kind = QueryKind::kList;
  long long wire_kind = 0;
  std::string entity_id;   ///< every kind but kList
  std::string frame_id;    ///< kPose
  std::string feature_id;  ///< kPose: empty for the entity itself
  double max_age_s = 0.0;  ///< kIsLocalized: maximum pose age, s; <= 0: any age
  /// kList: only entities of this kind; nullopt: all (or, with `list_kind_unknown`, a kind this build does
  /// not know, held in `wire_list_kind`).
  std::optional<EntityKind> list_kind;
  bool list_kind_unknown = false;
  long long wire_list_kind = 0;
};

/// rigger/world/reply: the answer to a Query. On !ok, `code` and `message` say why.
struct Reply {
  std::string client_id;
  std::uint64_t request_id = 0;
  bool ok = false;
  std::string code;
  std::string message;
  WallTime stamp{};   ///< of the pose
  std::string frame;  ///< the frame `pose_frame_entity` is expressed in
  Eigen::Isometry3d pose_frame_entity = Eigen::Isometry3d::Identity();  ///< m
  bool localized = false;
  double age_s = 0.0;
  std::string result_json;  ///< query-specific JSON text; empty: none
};

/// A pose as sent in an update: the quaternion is not normalised, so that a non-unit one can be refused.
struct PoseAsSent {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// rigger/world/update: a proposed change of one entity; absent parts stay as they are. Answered on
/// rigger/world/update_result with (`source`, `seq`).
struct Update {
  std::string source;
  std::uint64_t seq = 0;
  std::string entity_id;
  std::string parent_frame;  ///< non-empty: re-parent (then `pose` is in that frame)
  std::optional<PoseAsSent> pose;
  std::optional<Covariance6d> covariance;
  std::optional<double> quality;
  std::optional<bool> localized;
  /// When the information was observed; nullopt after from_wire when the sample's nanosec is >= 1e9.
  std::optional<WallTime> stamp;
  std::string attributes_json;  ///< empty: leave the attributes; else an RFC 7396 merge patch
};

/// rigger/world/update_result: the world model's verdict on an Update.
struct UpdateResult {
  std::string source;
  std::uint64_t seq = 0;
  std::string entity_id;
  bool accepted = false;
  std::string code;  ///< "ACCEPTED" or the rejection code ("STAMP_BACKWARDS", ...)
  std::string reason;
  std::uint64_t revision = 0;
};

/// rigger/world/entity: the current state of one entity.
struct EntityState {
  std::string entity_id;
  EntityKind kind = EntityKind::kFrame;
  std::string parent_frame;
  std::optional<Eigen::Isometry3d> pose_parent_entity;  ///< nullopt: not known (yet)
  Covariance6d covariance = Covariance6d::Zero();
  double quality = 0.0;
  bool localized = false;
  bool stale = false;
  WallTime stamp{};
  std::string source;
  std::string features_json;
  std::string attributes_json;
  std::uint64_t revision = 0;
};

/// rigger/world/change: who changed what, for journals and UIs.
struct EntityChange {
  std::string entity_id;
  std::uint64_t revision = 0;
  std::string source;
  std::string what;  ///< "pose,localized" style list of the changed parts
  WallTime stamp{};
};

void to_wire(const Query& query, rigger_world_WorldQuery& wire);
Query from_wire(const rigger_world_WorldQuery& wire);

void to_wire(const Reply& reply, rigger_world_WorldReply& wire);
Reply from_wire(const rigger_world_WorldReply& wire);

void to_wire(const Update& update, rigger_world_EntityUpdate& wire);
Update from_wire(const rigger_world_EntityUpdate& wire);

void to_wire(const UpdateResult& result, rigger_world_UpdateResult& wire);
UpdateResult from_wire(const rigger_world_UpdateResult& wire);

void to_wire(const EntityState& state, rigger_world_EntityState& wire);
/// An unknown kind reads as kFrame.
EntityState from_wire(const rigger_world_EntityState& wire);

void to_wire(const EntityChange& change, rigger_world_EntityChange& wire);
EntityChange from_wire(const rigger_world_EntityChange& wire);

}  // namespace rigger::world_protocol
