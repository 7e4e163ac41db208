#include "rigger/world_protocol/world_protocol.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::world_protocol {
namespace {

Eigen::Isometry3d pose_of(double x, double angle_rad) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(x, -0.25, 1.5);
  p.linear() = Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  return p;
}

WallTime stamp_of(std::int64_t unix_ns) {
  return from_unix_ns(unix_ns);
}

TEST(WorldProtocol, QueryRoundTrip) {
  Query q;
  q.client_id = "skills-1";
  q.request_id = 42;
  q.kind = QueryKind::kIsLocalized;
  q.entity_id = "beam";
  q.frame_id = "world";
  q.feature_id = "grasp";
  q.max_age_s = 0.5;
  rigger_world_WorldQuery wire{};
  to_wire(q, wire);
  EXPECT_EQ(wire.kind, rigger_world_QUERY_IS_LOCALIZED);
  const Query back = from_wire(wire);
  EXPECT_EQ(back.client_id, "skills-1");
  EXPECT_EQ(back.request_id, 42U);
  ASSERT_TRUE(back.kind.has_value());
  EXPECT_EQ(*back.kind, QueryKind::kIsLocalized);
  EXPECT_EQ(back.entity_id, "beam");
  EXPECT_EQ(back.frame_id, "world");
  EXPECT_EQ(back.feature_id, "grasp");
  EXPECT_EQ(back.max_age_s, 0.5);
}

TEST(WorldProtocol, EveryQueryKindRoundTrips) {
  for (QueryKind k :
       {QueryKind::kPose, QueryKind::kIsLocalized, QueryKind::kFeatures, QueryKind::kEntity, QueryKind::kList}) {
    Query q;
    q.kind = k;
    rigger_world_WorldQuery wire{};
    to_wire(q, wire);
    EXPECT_EQ(from_wire(wire).kind, k);
  }
}

TEST(WorldProtocol, AListKindFilterRoundTrips) {
  Query q;
  q.kind = QueryKind::kList;
  rigger_world_WorldQuery wire{};
  to_wire(q, wire);
  EXPECT_FALSE(wire.has_kind);
  EXPECT_FALSE(from_wire(wire).list_kind.has_value());
  for (EntityKind k : {EntityKind::kObject, EntityKind::kDevice, EntityKind::kFrame}) {
    q.list_kind = k;
    to_wire(q, wire);
    const Query back = from_wire(wire);
    EXPECT_EQ(back.list_kind, k);
    EXPECT_FALSE(back.list_kind_unknown);
  }
  wire.list_kind = static_cast<rigger_world_EntityKind>(12);
  const Query unknown = from_wire(wire);
  EXPECT_FALSE(unknown.list_kind.has_value());
  EXPECT_TRUE(unknown.list_kind_unknown);
  EXPECT_EQ(unknown.wire_list_kind, 12);
}

TEST(WorldProtocol, AnUnknownQueryKindIsKeptForTheMessage) {
  rigger_world_WorldQuery wire{};
  wire.kind = static_cast<rigger_world_QueryKind>(17);
  const Query q = from_wire(wire);
  EXPECT_FALSE(q.kind.has_value());
  EXPECT_EQ(q.wire_kind, 17);
  EXPECT_EQ(q.client_id, "");  // a null string reads as empty
  rigger_world_WorldQuery again{};
  to_wire(q, again);
  EXPECT_EQ(static_cast<int>(again.kind), 17);
}

TEST(WorldProtocol, ReplyRoundTrip) {
  Reply r;
  r.client_id = "tc";
  r.request_id = 7;
  r.ok = true;
  r.code = "OK";
  r.message = "fine";
  r.stamp = stamp_of(1'700'000'000'123'456'789);
  r.frame = "world";
  r.pose_frame_entity = pose_of(2.0, 0.7);
  r.localized = true;
  r.age_s = 0.125;
  r.result_json = R"({"features":[]})";
  rigger_world_WorldReply wire{};
  to_wire(r, wire);
  const Reply back = from_wire(wire);
  EXPECT_EQ(back.client_id, "tc");
  EXPECT_EQ(back.request_id, 7U);
  EXPECT_TRUE(back.ok);
  EXPECT_EQ(back.code, "OK");
  EXPECT_EQ(back.message, "fine");
  EXPECT_EQ(back.stamp, r.stamp);
  EXPECT_EQ(back.frame, "world");
  EXPECT_TRUE(back.pose_frame_entity.isApprox(r.pose_frame_entity, 1e-12));
  EXPECT_TRUE(back.localized);
  EXPECT_EQ(back.age_s, 0.125);
  EXPECT_EQ(back.result_json, r.result_json);
}

TEST(WorldProtocol, UpdateRoundTripKeepsWhatIsGivenAndOnlyThat) {
  Update u;
  u.source = "vision_tracker";
  u.seq = 9;
  u.entity_id = "beam";
  u.parent_frame = "crane_hook";
  u.pose = PoseAsSent{Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0)};  // not unit: kept
  Covariance6d cov = Covariance6d::Identity() * 0.01;
  cov(0, 1) = cov(1, 0) = 0.002;
  u.covariance = cov;
  u.quality = 0.8;
  u.localized = false;
  u.stamp = stamp_of(1'700'000'001'000'000'001);
  u.attributes_json = R"({"mass_kg":12})";
  rigger_world_EntityUpdate wire{};
  to_wire(u, wire);
  const Update back = from_wire(wire);
  EXPECT_EQ(back.source, "vision_tracker");
  EXPECT_EQ(back.seq, 9U);
  EXPECT_EQ(back.entity_id, "beam");
  EXPECT_EQ(back.parent_frame, "crane_hook");
  ASSERT_TRUE(back.pose.has_value());
  EXPECT_EQ(back.pose->position_m, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(back.pose->orientation.w(), 2.0);
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_EQ(*back.covariance, cov);
  EXPECT_EQ(back.quality, 0.8);
  EXPECT_EQ(back.localized, false);
  EXPECT_EQ(back.stamp, u.stamp);
  EXPECT_EQ(back.attributes_json, u.attributes_json);

  Update bare;
  bare.stamp = u.stamp;
  rigger_world_EntityUpdate bare_wire{};
  to_wire(bare, bare_wire);
  const Update bare_back = from_wire(bare_wire);
  EXPECT_FALSE(bare_back.pose || bare_back.covariance || bare_back.quality || bare_back.localized);
}

TEST(WorldProtocol, AnUpdateStampWithTooManyNanosecondsIsNoStamp) {
  rigger_world_EntityUpdate wire{};
  wire.stamp.sec = 5;
  wire.stamp.nanosec = 1000000000u;
  EXPECT_FALSE(from_wire(wire).stamp.has_value());
  wire.stamp.nanosec = 999999999u;
  EXPECT_TRUE(from_wire(wire).stamp.has_value());
}

TEST(WorldProtocol, UpdateResultRoundTrip) {
  UpdateResult r{"skills", 3, "beam", false, "STAMP_BACKWARDS", "older than revision 4", 4};
  rigger_world_UpdateResult wire{};
  to_wire(r, wire);
  const UpdateResult back = from_wire(wire);
  EXPECT_EQ(back.source, "skills");
  EXPECT_EQ(back.seq, 3U);
  EXPECT_EQ(back.entity_id, "beam");
  EXPECT_FALSE(back.accepted);
  EXPECT_EQ(back.code, "STAMP_BACKWARDS");
  EXPECT_EQ(back.reason, "older than revision 4");
  EXPECT_EQ(back.revision, 4U);
}

TEST(WorldProtocol, EntityStateRoundTrip) {
  for (EntityKind kind : {EntityKind::kObject, EntityKind::kDevice, EntityKind::kFrame}) {
    EntityState s;
    s.entity_id = "beam";
    s.kind = kind;
    s.parent_frame = "world";
    s.pose_parent_entity = pose_of(-1.0, 1.2);
    s.covariance = Covariance6d::Identity() * 0.5;
    s.quality = 0.9;
    s.localized = true;
    s.stale = true;
    s.stamp = stamp_of(1'700'000'002'500'000'000);
    s.source = "cell";
    s.features_json = "{}";
    s.attributes_json = R"({"a":1})";
    s.revision = 11;
    rigger_world_EntityState wire{};
    to_wire(s, wire);
    const EntityState back = from_wire(wire);
    EXPECT_EQ(back.entity_id, "beam");
    EXPECT_EQ(back.kind, kind);
    EXPECT_EQ(back.parent_frame, "world");
    ASSERT_TRUE(back.pose_parent_entity.has_value());
    EXPECT_TRUE(back.pose_parent_entity->isApprox(*s.pose_parent_entity, 1e-12));
    EXPECT_EQ(back.covariance, s.covariance);
    EXPECT_EQ(back.quality, 0.9);
    EXPECT_TRUE(back.localized);
    EXPECT_TRUE(back.stale);
    EXPECT_EQ(back.stamp, s.stamp);
    EXPECT_EQ(back.source, "cell");
    EXPECT_EQ(back.features_json, "{}");
    EXPECT_EQ(back.attributes_json, s.attributes_json);
    EXPECT_EQ(back.revision, 11U);
  }
  EntityState no_pose;
  rigger_world_EntityState wire{};
  to_wire(no_pose, wire);
  EXPECT_FALSE(wire.has_pose);
  EXPECT_FALSE(from_wire(wire).pose_parent_entity.has_value());
}

TEST(WorldProtocol, EntityChangeRoundTrip) {
  EntityChange c{"beam", 12, "skills", "pose,localized", stamp_of(1'700'000'003'000'000'007)};
  rigger_world_EntityChange wire{};
  to_wire(c, wire);
  const EntityChange back = from_wire(wire);
  EXPECT_EQ(back.entity_id, "beam");
  EXPECT_EQ(back.revision, 12U);
  EXPECT_EQ(back.source, "skills");
  EXPECT_EQ(back.what, "pose,localized");
  EXPECT_EQ(back.stamp, c.stamp);
}

}  // namespace
}  // namespace rigger::world_protocol
