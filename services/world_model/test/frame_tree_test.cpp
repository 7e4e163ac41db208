#include <cmath>

#include <gtest/gtest.h>

#include "cell_fixture.hpp"

#include "world_cell_config.hpp"
#include "world_frame_tree.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

constexpr double kPi = 3.14159265358979323846;

Entity make_entity(const std::string& id, const std::string& parent, const Eigen::Isometry3d* pose, Stamp stamp = Stamp{},
                   bool localized = true) {
  Entity entity;
  entity.id = id;
  entity.kind = parent.empty() ? EntityKind::kFrame : EntityKind::kObject;
  entity.parent = parent;
  if (pose != nullptr) {
    PoseEstimate estimate;
    estimate.pose_parent_entity = *pose;
    estimate.stamp = stamp;
    entity.pose = estimate;
  }
  entity.localized = localized && pose != nullptr;
  return entity;
}

Eigen::Isometry3d make_pose(const Eigen::Vector3d& t, const Eigen::Matrix3d& r) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  pose.translation() = t;
  return pose;
}

// world ── a (at (1,0,0), yaw 90°) ── b (at (0,2,0) in a, no rotation)
//       └─ c (at (0,0,1), roll 180°)
class FrameTreeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rz90_ << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    rx180_ << 1, 0, 0, 0, -1, 0, 0, 0, -1;
    const Eigen::Isometry3d pose_world_a = make_pose({1, 0, 0}, rz90_);
    const Eigen::Isometry3d pose_a_b = make_pose({0, 2, 0}, Eigen::Matrix3d::Identity());
    const Eigen::Isometry3d pose_world_c = make_pose({0, 0, 1}, rx180_);
    add(make_entity("world", "", nullptr));
    add(make_entity("a", "world", &pose_world_a, Stamp(std::chrono::seconds(30))));
    add(make_entity("b", "a", &pose_a_b, Stamp(std::chrono::seconds(20))));
    add(make_entity("c", "world", &pose_world_c, Stamp(std::chrono::seconds(40))));
  }
  void add(Entity entity) {
    const std::string id = entity.id;
    entities_.emplace(id, std::move(entity));
  }

  Eigen::Matrix3d rz90_;
  Eigen::Matrix3d rx180_;
  EntityMap entities_;
};

TEST_F(FrameTreeTest, ComposesDownTheTree) {
  // b in world: Rz(90)·(0,2,0) + (1,0,0) = (-2,0,0) + (1,0,0) = (-1,0,0); rotation Rz(90).
  const auto result = pose_in_frame(entities_, "b", "world");
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
  EXPECT_TRUE(result.value.pose_frame_entity.linear().isApprox(rz90_, 1e-12));
  ASSERT_TRUE(result.value.oldest_stamp.has_value());
  EXPECT_EQ(*result.value.oldest_stamp, Stamp(std::chrono::seconds(20)));
  EXPECT_TRUE(result.value.all_localized);
}

TEST_F(FrameTreeTest, ComposesThroughTheCommonAncestor) {
  // b in c: T_c_world = (Rx(180), (0,0,1)) since Rx(180) is its own inverse and −Rx(180)·(0,0,1) = (0,0,1).
  // Position: Rx(180)·(-1,0,0) + (0,0,1) = (-1,0,1). Rotation: Rx(180)·Rz(90) = [[0,-1,0],[-1,0,0],[0,0,-1]].
  const auto result = pose_in_frame(entities_, "b", "c");
  ASSERT_TRUE(result.ok()) << result.message;
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, -1, 0, 0, 0, 0, -1;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(-1, 0, 1), 1e-12));
  EXPECT_TRUE(result.value.pose_frame_entity.linear().isApprox(expected, 1e-12));
  EXPECT_EQ(*result.value.oldest_stamp, Stamp(std::chrono::seconds(20)));
}

TEST_F(FrameTreeTest, UpTheTreeIsTheInverse) {
  // world in b: inverse of (Rz(90), (-1,0,0)) = (Rz(-90), −Rz(-90)·(-1,0,0)) = (Rz(-90), (0,-1,0)).
  const auto result = pose_in_frame(entities_, "world", "b");
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));
  EXPECT_TRUE(result.value.pose_frame_entity.linear().isApprox(rz90_.transpose(), 1e-12));
}

TEST_F(FrameTreeTest, ChildInItsParentIsItsOwnPose) {
  const auto result = pose_in_frame(entities_, "b", "a");
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0, 2, 0), 1e-12));
  EXPECT_TRUE(result.value.pose_frame_entity.linear().isIdentity(1e-12));
}

TEST_F(FrameTreeTest, AnEntityInItselfIsIdentityWithoutStamp) {
  const auto result = pose_in_frame(entities_, "b", "b");
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result.value.pose_frame_entity.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_FALSE(result.value.oldest_stamp.has_value());
}

TEST_F(FrameTreeTest, ReportsLocalizationAndStalenessAlongThePath) {
  entities_.at("a").localized = false;
  entities_.at("c").stale = true;
  const auto result = pose_in_frame(entities_, "b", "c");
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result.value.all_localized);
  EXPECT_TRUE(result.value.any_stale);
  const auto only_c = pose_in_frame(entities_, "c", "world");
  EXPECT_TRUE(only_c.value.all_localized);
  EXPECT_TRUE(only_c.value.any_stale);
}

TEST_F(FrameTreeTest, UnknownEntityOrFrame) {
  EXPECT_EQ(pose_in_frame(entities_, "nope", "world").status, QueryStatus::kUnknownEntity);
  const auto result = pose_in_frame(entities_, "b", "nope");
  EXPECT_EQ(result.status, QueryStatus::kUnknownEntity);
  EXPECT_NE(result.message.find("\"nope\""), std::string::npos);
  EXPECT_EQ(to_code(result.status), "UNKNOWN_ENTITY");
}

TEST_F(FrameTreeTest, AnUnknownParentOnThePath) {
  entities_.at("a").parent = "ghost";
  const auto result = pose_in_frame(entities_, "b", "world");
  EXPECT_EQ(result.status, QueryStatus::kUnknownEntity);
  EXPECT_NE(result.message.find("unknown parent \"ghost\""), std::string::npos) << result.message;
}

TEST_F(FrameTreeTest, AMissingPoseOnThePathIsNamed) {
  entities_.at("a").pose.reset();
  const auto result = pose_in_frame(entities_, "b", "c");
  EXPECT_EQ(result.status, QueryStatus::kPoseUnknown);
  EXPECT_NE(result.message.find("\"a\""), std::string::npos) << result.message;
  // Above the missing pose, the tree still answers.
  EXPECT_TRUE(pose_in_frame(entities_, "b", "a").ok());
}

TEST_F(FrameTreeTest, SeparateTreesShareNoFrame) {
  add(make_entity("other_root", "", nullptr));
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  add(make_entity("d", "other_root", &identity));
  const auto result = pose_in_frame(entities_, "d", "b");
  EXPECT_EQ(result.status, QueryStatus::kNoCommonAncestor);
  EXPECT_EQ(to_code(result.status), "NO_COMMON_ANCESTOR");
}

TEST_F(FrameTreeTest, ACycleIsReportedNotLooped) {
  entities_.at("a").parent = "b";  // a -> b -> a
  EXPECT_EQ(pose_in_frame(entities_, "b", "world").status, QueryStatus::kFrameCycle);
  EXPECT_EQ(path_to_root(entities_, "a").status, QueryStatus::kFrameCycle);
}

TEST_F(FrameTreeTest, SelfOrAncestor) {
  EXPECT_TRUE(is_self_or_ancestor(entities_, "a", "b"));
  EXPECT_TRUE(is_self_or_ancestor(entities_, "world", "b"));
  EXPECT_TRUE(is_self_or_ancestor(entities_, "b", "b"));
  EXPECT_FALSE(is_self_or_ancestor(entities_, "b", "a"));
  EXPECT_FALSE(is_self_or_ancestor(entities_, "c", "b"));
  EXPECT_FALSE(is_self_or_ancestor(entities_, "a", "nope"));
}

TEST(FrameTreeCell, LoadInTheCameraFrameOfTheSimulatedCell) {
  const CellConfig config = load_cell_config(testing::fixture_cell_path());
  const WorldStore store = WorldStore::from_config(config, Stamp(std::chrono::seconds(100)));
  // Camera at (3.55, 0.6, 2.2) with R = Rx(-130°); load at (3.55, 1.75, 1.2).
  // p = Rx(130°)·(0, 1.15, -1.0) = (0, 1.15 cos130° + sin130°, 1.15 sin130° − cos130°).
  const double c = std::cos(130.0 * kPi / 180.0);
  const double s = std::sin(130.0 * kPi / 180.0);
  const auto result = pose_in_frame(store.entities(), "load", "camera");
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(result.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0, 1.15 * c + s, 1.15 * s - c), 1e-12));
  EXPECT_GT(result.value.pose_frame_entity.translation().z(), 1.0) << "the load is in front of the camera";
  EXPECT_FALSE(result.value.all_localized) << "the load is not localized until perception says so";
  // The gripper has no pose until the robot reports one.
  EXPECT_EQ(pose_in_frame(store.entities(), "gripper", "world").status, QueryStatus::kPoseUnknown);
}

}  // namespace
}  // namespace rigger::world
