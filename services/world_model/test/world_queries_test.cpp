#include <gtest/gtest.h>

#include "cell_fixture.hpp"

#include "world_cell_config.hpp"
#include "world_queries.hpp"

namespace rigger::world {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

const Stamp kLoadedAt{seconds(1000)};

class WorldQueriesTest : public ::testing::Test {
 protected:
  WorldQueriesTest()
      : store_(WorldStore::from_config(load_cell_config(testing::fixture_cell_path()),
                                       kLoadedAt)) {}

  void localize_load(Stamp stamp) {
    EntityUpdate update;
    update.entity_id = "load";
    update.source = "vision_tracker";
    update.stamp = stamp;
    update.pose = PoseValue{Eigen::Vector3d(3.55, 1.75, 1.20), Eigen::Quaterniond::Identity()};
    ASSERT_TRUE(store_.apply(update).accepted());
  }

  WorldStore store_;
};

TEST_F(WorldQueriesTest, PoseOfAGraspFrameInTheRobotFrame) {
  // Load at (3.55, 1.75, 1.20) in world, grasp_side at (-0.20, 0, 0) with Ry(90°) in the load:
  // (3.35, 1.75, 1.20) in world; the robot base at (2.55, 2.0, 0.9) → (0.80, -0.25, 0.30) in the robot.
  const auto result = feature_pose_of(store_, "load", "grasp_side", "robot");
  ASSERT_TRUE(result.ok()) << result.message;
  Eigen::Matrix3d ry90;
  ry90 << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0.80, -0.25, 0.30), 1e-12));
  EXPECT_TRUE(result.value.pose_frame_entity.linear().isApprox(ry90, 1e-12));
  EXPECT_FALSE(result.value.all_localized);
}

TEST_F(WorldQueriesTest, PoseOfAScrewHoleInWorld) {
  // Target at (3.55, 2.25, 0.95), hole h3 at (0.15, 0.10, 0) → (3.70, 2.35, 0.95).
  const auto result = feature_pose_of(store_, "target", "h3", "world");
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(3.70, 2.35, 0.95), 1e-12));
}

TEST_F(WorldQueriesTest, FeatureErrors) {
  EXPECT_EQ(feature_pose_of(store_, "load", "h3", "world").status, QueryStatus::kUnknownFeature);
  EXPECT_EQ(feature_pose_of(store_, "crate", "h3", "world").status, QueryStatus::kUnknownEntity);
  EXPECT_EQ(feature_pose_of(store_, "load", "grasp_side", "nowhere").status, QueryStatus::kUnknownEntity);
  EXPECT_EQ(feature_pose_of(store_, "load", "grasp_side", "gripper").status, QueryStatus::kPoseUnknown);
}

TEST_F(WorldQueriesTest, PoseOfGoesThroughTheTree) {
  const auto result = pose_of(store_, "target", "load");
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0, 0.5, -0.25), 1e-12));
  EXPECT_EQ(pose_of(store_, "load", "nope").status, QueryStatus::kUnknownEntity);
}

TEST_F(WorldQueriesTest, ObjectsAreNotLocalizedUntilObserved) {
  const auto result = is_localized(store_, "load", seconds(5), kLoadedAt);
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result.value.localized);
  EXPECT_EQ(result.value.state, LocalizationState::kNotLocalized);
  EXPECT_EQ(to_code(result.value.state), "NOT_LOCALIZED");
}

TEST_F(WorldQueriesTest, LocalizedWithinMaxAge) {
  localize_load(kLoadedAt + seconds(10));
  const auto fresh = is_localized(store_, "load", seconds(5), kLoadedAt + seconds(14));
  ASSERT_TRUE(fresh.ok());
  EXPECT_TRUE(fresh.value.localized) << fresh.value.message;
  EXPECT_EQ(fresh.value.state, LocalizationState::kLocalized);
  EXPECT_EQ(*fresh.value.age, seconds(4));
  // Exactly at the max age still counts; one millisecond later does not.
  EXPECT_TRUE(is_localized(store_, "load", seconds(5), kLoadedAt + seconds(15)).value.localized);
  const auto old = is_localized(store_, "load", seconds(5), kLoadedAt + seconds(15) + milliseconds(1));
  EXPECT_FALSE(old.value.localized);
  EXPECT_EQ(old.value.state, LocalizationState::kTooOld);
  EXPECT_NE(old.value.message.find("5.001 s ago"), std::string::npos) << old.value.message;
  // Without a max age, any age will do.
  EXPECT_TRUE(is_localized(store_, "load", std::nullopt, kLoadedAt + seconds(3600)).value.localized);
}

TEST_F(WorldQueriesTest, AStampAheadOfNowCountsAsFresh) {
  localize_load(kLoadedAt + seconds(10));
  const auto result = is_localized(store_, "load", milliseconds(100), kLoadedAt + seconds(9));
  EXPECT_TRUE(result.value.localized);
  EXPECT_EQ(*result.value.age, std::chrono::nanoseconds(0));
}

TEST_F(WorldQueriesTest, NoPoseAndUnknownEntity) {
  const auto gripper = is_localized(store_, "gripper", std::nullopt, kLoadedAt);
  ASSERT_TRUE(gripper.ok());
  EXPECT_EQ(gripper.value.state, LocalizationState::kNoPose);
  EXPECT_FALSE(gripper.value.age.has_value());
  EXPECT_EQ(is_localized(store_, "crate", std::nullopt, kLoadedAt).status, QueryStatus::kUnknownEntity);
}

TEST_F(WorldQueriesTest, CalibratedDevicesAreLocalizedByTheConfiguration) {
  EXPECT_TRUE(is_localized(store_, "camera", std::nullopt, kLoadedAt + seconds(3600)).value.localized);
  EXPECT_EQ(is_localized(store_, "camera", seconds(1), kLoadedAt + seconds(3600)).value.state, LocalizationState::kTooOld);
}

TEST_F(WorldQueriesTest, FeaturesOfAnObject) {
  const auto result = features_of(store_, "target");
  ASSERT_TRUE(result.ok());
  ASSERT_EQ(result.value.screw_holes.size(), 4u);
  EXPECT_EQ(result.value.screw_holes[0].id, "h1");
  EXPECT_TRUE(features_of(store_, "robot").value.empty());
  EXPECT_EQ(features_of(store_, "crate").status, QueryStatus::kUnknownEntity);
}

TEST_F(WorldQueriesTest, ListsEntitiesInIdOrder) {
  EXPECT_EQ(list_entities(store_),
            (std::vector<std::string>{"camera", "crane", "gripper", "load", "robot", "target", "world"}));
  EXPECT_EQ(list_entities(store_, EntityKind::kObject), (std::vector<std::string>{"load", "target"}));
  EXPECT_EQ(list_entities(store_, EntityKind::kFrame), (std::vector<std::string>{"world"}));
}

}  // namespace
}  // namespace rigger::world
