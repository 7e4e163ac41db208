// Query answers as the reply carries them, from the fixture cell.
#include "world_answers.hpp"

#include <gtest/gtest.h>

#include "cell_fixture.hpp"
#include "wire_decoding.hpp"
#include "world_cell_config.hpp"

namespace rigger::world {
namespace {

using std::chrono::seconds;

const Stamp kLoadedAt{seconds(1000)};

class WorldAnswersTest : public ::testing::Test {
 protected:
  WorldAnswersTest() : store_(WorldStore::from_config(load_cell_config(testing::fixture_cell_path()), kLoadedAt)) {}

  WorldQuery query(QueryKind kind, std::string entity, std::string frame = "", std::string feature = "") {
    WorldQuery q;
    q.kind = kind;
    q.entity_id = std::move(entity);
    q.frame_id = std::move(frame);
    q.feature_id = std::move(feature);
    return q;
  }
  void localize_load(Stamp stamp) {
    EntityUpdate u;
    u.entity_id = "load";
    u.source = "tracker";
    u.stamp = stamp;
    u.pose = PoseValue{Eigen::Vector3d(3.55, 1.75, 1.20), Eigen::Quaterniond::Identity()};
    ASSERT_TRUE(store_.apply(u).accepted());
  }

  WorldStore store_;
};

TEST_F(WorldAnswersTest, PoseOfTheLoadInTheRobotFrameWithItsAge) {
  localize_load(kLoadedAt + seconds(10));
  const auto a = answer_query(store_, query(QueryKind::kPose, "load", "robot"), kLoadedAt + seconds(12));
  ASSERT_TRUE(a.ok) << a.message;
  // Load (3.55, 1.75, 1.20) − robot base (2.55, 2.0, 0.9).
  EXPECT_TRUE(a.pose_frame_entity.translation().isApprox(Eigen::Vector3d(1.0, -0.25, 0.30), 1e-12));
  EXPECT_EQ(a.frame, "robot");
  EXPECT_TRUE(a.localized);
  // The oldest pose on the path is the robot's configuration pose (loaded at kLoadedAt).
  EXPECT_DOUBLE_EQ(a.age_s, 12.0);
  EXPECT_EQ(a.result["all_localized"], true);
}

TEST_F(WorldAnswersTest, FeaturePoseNamesTheFeature) {
  const auto a = answer_query(store_, query(QueryKind::kPose, "target", "world", "h3"), kLoadedAt);
  ASSERT_TRUE(a.ok) << a.message;
  EXPECT_TRUE(a.pose_frame_entity.translation().isApprox(Eigen::Vector3d(3.70, 2.35, 0.95), 1e-12));
  EXPECT_FALSE(a.localized);  // the target is not localized until observed
  const auto missing = answer_query(store_, query(QueryKind::kPose, "target", "world", "h99"), kLoadedAt);
  EXPECT_FALSE(missing.ok);
  EXPECT_EQ(missing.code, "UNKNOWN_FEATURE");
}

TEST_F(WorldAnswersTest, ErrorsCarryTheQueryCode) {
  EXPECT_EQ(answer_query(store_, query(QueryKind::kPose, "crate", "world"), kLoadedAt).code, "UNKNOWN_ENTITY");
  EXPECT_EQ(answer_query(store_, query(QueryKind::kPose, "gripper", "world"), kLoadedAt).code, "POSE_UNKNOWN");
  EXPECT_EQ(answer_query(store_, query(QueryKind::kEntity, "crate"), kLoadedAt).code, "UNKNOWN_ENTITY");
  EXPECT_EQ(answer_query(store_, query(QueryKind::kFeatures, "crate"), kLoadedAt).code, "UNKNOWN_ENTITY");
  EXPECT_EQ(answer_query(store_, query(QueryKind::kIsLocalized, "crate"), kLoadedAt).code, "UNKNOWN_ENTITY");
}

TEST_F(WorldAnswersTest, IsLocalizedAnswersOkWithTheStateCode) {
  auto q = query(QueryKind::kIsLocalized, "load");
  auto a = answer_query(store_, q, kLoadedAt);
  EXPECT_TRUE(a.ok);
  EXPECT_FALSE(a.localized);
  EXPECT_EQ(a.code, "NOT_LOCALIZED");
  localize_load(kLoadedAt + seconds(1));
  q.max_age = seconds(2);
  a = answer_query(store_, q, kLoadedAt + seconds(2));
  EXPECT_TRUE(a.localized);
  EXPECT_EQ(a.code, "LOCALIZED");
  EXPECT_DOUBLE_EQ(a.age_s, 1.0);
  a = answer_query(store_, q, kLoadedAt + seconds(4));
  EXPECT_FALSE(a.localized);
  EXPECT_EQ(a.code, "TOO_OLD");
  EXPECT_DOUBLE_EQ(a.age_s, 3.0);
}

TEST_F(WorldAnswersTest, FeaturesEntityAndList) {
  const auto f = answer_query(store_, query(QueryKind::kFeatures, "load"), kLoadedAt);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.result["grasp_frames"][0]["id"], "grasp_side");
  const auto e = answer_query(store_, query(QueryKind::kEntity, "robot"), kLoadedAt);
  ASSERT_TRUE(e.ok);
  EXPECT_EQ(e.result["id"], "robot");
  EXPECT_EQ(e.frame, "world");
  EXPECT_TRUE(e.pose_frame_entity.translation().isApprox(Eigen::Vector3d(2.55, 2.0, 0.9), 1e-12));
  const auto l = answer_query(store_, query(QueryKind::kList, ""), kLoadedAt);
  ASSERT_TRUE(l.ok);
  EXPECT_EQ(l.result, nlohmann::json({"camera", "crane", "gripper", "load", "robot", "target", "world"}));
  WorldQuery objects = query(QueryKind::kList, "");
  objects.list_kind = EntityKind::kObject;
  EXPECT_EQ(answer_query(store_, objects, kLoadedAt).result, nlohmann::json({"load", "target"}));
}

TEST(WireDecoding, AListKindIsDecodedAndAnUnknownOneRefused) {
  world_protocol::Query sent;
  sent.client_id = "c";
  sent.kind = QueryKind::kList;
  sent.list_kind = world_protocol::EntityKind::kDevice;
  const auto decoded = decode_query(sent);
  ASSERT_TRUE(std::holds_alternative<WorldQuery>(decoded));
  EXPECT_EQ(std::get<WorldQuery>(decoded).list_kind, EntityKind::kDevice);
  sent.list_kind.reset();
  sent.list_kind_unknown = true;
  sent.wire_list_kind = 7;
  const auto refused = decode_query(sent);
  ASSERT_TRUE(std::holds_alternative<DecodeError>(refused));
  EXPECT_EQ(std::get<DecodeError>(refused).code, "BAD_QUERY");
}

}  // namespace
}  // namespace rigger::world
