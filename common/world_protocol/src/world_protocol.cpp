#include "rigger/world_protocol/world_protocol.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::world_protocol {
namespace {

rigger_world_QueryKind kind_to_wire(QueryKind kind) {
  switch (kind) {
    case QueryKind::kPose:
      return rigger_world_QUERY_POSE;
    case QueryKind::kIsLocalized:
      return rigger_world_QUERY_IS_LOCALIZED;
    case QueryKind::kFeatures:
      return rigger_world_QUERY_FEATURES;
    case QueryKind::kEntity:
      return rigger_world_QUERY_ENTITY;
    case QueryKind::kList:
      return rigger_world_QUERY_LIST;
  }
  return rigger_world_QUERY_LIST;
}

std::optional<QueryKind> kind_from_wire(rigger_world_QueryKind kind) {
  switch (kind) {
    case rigger_world_QUERY_POSE:
      return QueryKind::kPose;
    case rigger_world_QUERY_IS_LOCALIZED:
      return QueryKind::kIsLocalized;
    case rigger_world_QUERY_FEATURES:
      return QueryKind::kFeatures;
    case rigger_world_QUERY_ENTITY:
      return QueryKind::kEntity;
    case rigger_world_QUERY_LIST:
      return QueryKind::kList;
  }
  return std::nullopt;
}

rigger_world_EntityKind kind_to_wire(EntityKind kind) {
  switch (kind) {
    case EntityKind::kObject:
      return rigger_world_ENTITY_OBJECT;
    case EntityKind::kDevice:
      return rigger_world_ENTITY_DEVICE;
    case EntityKind::kFrame:
      return rigger_world_ENTITY_FRAME;
  }
  return rigger_world_ENTITY_FRAME;
}

std::optional<EntityKind> known_kind_from_wire(rigger_world_EntityKind kind) {
  switch (kind) {
    case rigger_world_ENTITY_OBJECT:
      return EntityKind::kObject;
    case rigger_world_ENTITY_DEVICE:
      return EntityKind::kDevice;
    case rigger_world_ENTITY_FRAME:
      return EntityKind::kFrame;
  }
  return std::nullopt;
}

EntityKind kind_from_wire(rigger_world_EntityKind kind) {
  return known_kind_from_wire(kind).value_or(EntityKind::kFrame);
}

}  // namespace

void to_wire(const Query& query, rigger_world_WorldQuery& wire) {
  wire.client_id = dds::wire_string(query.client_id);
  wire.request_id = query.request_id;
  wire.kind = query.kind ? kind_to_wire(*query.kind) : static_cast<rigger_world_QueryKind>(query.wire_kind);
  wire.entity_id = dds::wire_string(query.entity_id);
  wire.frame_id = dds::wire_string(query.frame_id);
  wire.feature_id = dds::wire_string(query.feature_id);
  wire.max_age_s = query.max_age_s;
  wire.has_kind = query.list_kind.has_value() || query.list_kind_unknown;
  wire.list_kind =
      query.list_kind ? kind_to_wire(*query.list_kind) : static_cast<rigger_world_EntityKind>(query.wire_list_kind);
}

Query from_wire(const rigger_world_WorldQuery& wire) {
  Query q;
  q.client_id = dds::to_string(wire.client_id);
  q.request_id = wire.request_id;
  q.kind = kind_from_wire(wire.kind);
  q.wire_kind = static_cast<long long>(wire.kind);
  q.entity_id = dds::to_string(wire.entity_id);
  q.frame_id = dds::to_string(wire.frame_id);
  q.feature_id = dds::to_string(wire.feature_id);
  q.max_age_s = wire.max_age_s;
  if (wire.has_kind) {
    q.list_kind = known_kind_from_wire(wire.list_kind);
    q.list_kind_unknown = !q.list_kind;
    q.wire_list_kind = static_cast<long long>(wire.list_kind);
  }
  return q;
}

void to_wire(const Reply& reply, rigger_world_WorldReply& wire) {
  wire.client_id = dds::wire_string(reply.client_id);
  wire.request_id = reply.request_id;
  wire.ok = reply.ok;
  wire.code = dds::wire_string(reply.code);
  wire.message = dds::wire_string(reply.message);
  wire.pose.header.stamp = dds::to_wire(reply.stamp);
  wire.pose.header.frame_id = dds::wire_string(reply.frame);
  wire.pose.pose = dds::to_wire(reply.pose_frame_entity);
  wire.localized = reply.localized;
  wire.age_s = reply.age_s;
  wire.result_json = dds::wire_string(reply.result_json);
}

Reply from_wire(const rigger_world_WorldReply& wire) {
  Reply r;
  r.client_id = dds::to_string(wire.client_id);
  r.request_id = wire.request_id;
  r.ok = wire.ok;
  r.code = dds::to_string(wire.code);
  r.message = dds::to_string(wire.message);
  r.stamp = dds::to_domain(wire.pose.header.stamp);
  r.frame = dds::to_string(wire.pose.header.frame_id);
  r.pose_frame_entity = dds::to_domain(wire.pose.pose);
  r.localized = wire.localized;
  r.age_s = wire.age_s;
  r.result_json = dds::to_string(wire.result_json);
  return r;
}

void to_wire(const Update& update, rigger_world_EntityUpdate& wire) {
  wire.source = dds::wire_string(update.source);
  wire.seq = update.seq;
  wire.entity_id = dds::wire_string(update.entity_id);
  wire.parent_frame = dds::wire_string(update.parent_frame);
  wire.has_pose = update.pose.has_value();
  if (update.pose) {
    // Position and quaternion as given, not through an Isometry3d, which cannot carry a non-unit quaternion.
    wire.pose.pose.position = dds::to_wire_point(update.pose->position_m);
    wire.pose.pose.orientation = dds::to_wire(update.pose->orientation);
  }
  wire.has_covariance = update.covariance.has_value();
  if (update.covariance) dds::covariance_to_wire(*update.covariance, wire.pose.covariance);
  wire.has_quality = update.quality.has_value();
  wire.quality = update.quality.value_or(0.0);
  wire.has_localized = update.localized.has_value();
  wire.localized = update.localized.value_or(false);
  // An update without a valid stamp is the world model's to refuse: sent as the epoch.
  wire.stamp = dds::to_wire(update.stamp.value_or(WallTime{}));
  wire.attributes_json = dds::wire_string(update.attributes_json);
}

Update from_wire(const rigger_world_EntityUpdate& wire) {
  Update u;
  u.source = dds::to_string(wire.source);
  u.seq = wire.seq;
  u.entity_id = dds::to_string(wire.entity_id);
  u.parent_frame = dds::to_string(wire.parent_frame);
  if (wire.has_pose) {
    const auto& p = wire.pose.pose;
    u.pose = PoseAsSent{dds::to_domain(p.position), dds::to_domain(p.orientation)};
  }
  if (wire.has_covariance) u.covariance = dds::covariance_to_domain(wire.pose.covariance);
  if (wire.has_quality) u.quality = wire.quality;
  if (wire.has_localized) u.localized = wire.localized;
  if (wire.stamp.nanosec < 1000000000u) u.stamp = dds::to_domain(wire.stamp);
  u.attributes_json = dds::to_string(wire.attributes_json);
  return u;
}

void to_wire(const UpdateResult& result, rigger_world_UpdateResult& wire) {
  wire.source = dds::wire_string(result.source);
  wire.seq = result.seq;
  wire.entity_id = dds::wire_string(result.entity_id);
  wire.accepted = result.accepted;
  wire.code = dds::wire_string(result.code);
  wire.reason = dds::wire_string(result.reason);
  wire.revision = result.revision;
}

UpdateResult from_wire(const rigger_world_UpdateResult& wire) {
  UpdateResult r;
  r.source = dds::to_string(wire.source);
  r.seq = wire.seq;
  r.entity_id = dds::to_string(wire.entity_id);
  r.accepted = wire.accepted;
  r.code = dds::to_string(wire.code);
  r.reason = dds::to_string(wire.reason);
  r.revision = wire.revision;
  return r;
}

void to_wire(const EntityState& state, rigger_world_EntityState& wire) {
  wire.entity_id = dds::wire_string(state.entity_id);
  wire.kind = kind_to_wire(state.kind);
  wire.parent_frame = dds::wire_string(state.parent_frame);
  wire.has_pose = state.pose_parent_entity.has_value();
  wire.pose.pose = dds::to_wire(state.pose_parent_entity.value_or(Eigen::Isometry3d::Identity()));
  dds::covariance_to_wire(state.covariance, wire.pose.covariance);
  wire.quality = state.quality;
  wire.localized = state.localized;
  wire.stale = state.stale;
  wire.stamp = dds::to_wire(state.stamp);
  wire.source = dds::wire_string(state.source);
  wire.features_json = dds::wire_string(state.features_json);
  wire.attributes_json = dds::wire_string(state.attributes_json);
  wire.revision = state.revision;
}

EntityState from_wire(const rigger_world_EntityState& wire) {
  EntityState s;
  s.entity_id = dds::to_string(wire.entity_id);
  s.kind = kind_from_wire(wire.kind);
  s.parent_frame = dds::to_string(wire.parent_frame);
  if (wire.has_pose) s.pose_parent_entity = dds::to_domain(wire.pose.pose);
  s.covariance = dds::covariance_to_domain(wire.pose.covariance);
  s.quality = wire.quality;
  s.localized = wire.localized;
  s.stale = wire.stale;
  s.stamp = dds::to_domain(wire.stamp);
  s.source = dds::to_string(wire.source);
  s.features_json = dds::to_string(wire.features_json);
  s.attributes_json = dds::to_string(wire.attributes_json);
  s.revision = wire.revision;
  return s;
}

void to_wire(const EntityChange& change, rigger_world_EntityChange& wire) {
  wire.entity_id = dds::wire_string(change.entity_id);
  wire.revision = change.revision;
  wire.source = dds::wire_string(change.source);
  wire.what = dds::wire_string(change.what);
  wire.stamp = dds::to_wire(change.stamp);
}

EntityChange from_wire(const rigger_world_EntityChange& wire) {
  EntityChange c;
  c.entity_id = dds::to_string(wire.entity_id);
  c.revision = wire.revision;
  c.source = dds::to_string(wire.source);
  c.what = dds::to_string(wire.what);
  c.stamp = dds::to_domain(wire.stamp);
  return c;
}

}  // namespace rigger::world_protocol
