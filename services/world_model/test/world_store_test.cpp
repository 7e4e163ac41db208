#include <cmath>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "cell_fixture.hpp"

#include "world_cell_config.hpp"
#include "world_frame_tree.hpp"
#include "world_json.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

using nlohmann::json;
using std::chrono::milliseconds;
using std::chrono::seconds;

const Stamp kLoadedAt{seconds(1000)};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

class WorldStoreTest : public ::testing::Test {
 protected:
  WorldStoreTest()
      : store_(WorldStore::from_config(load_cell_config(testing::fixture_cell_path()),
                                       kLoadedAt)) {}

  // An update that changes nothing yet.
  static EntityUpdate bare_update(const std::string& id, Stamp stamp, const std::string& source = "vision_tracker") {
    EntityUpdate update;
    update.entity_id = id;
    update.source = source;
    update.stamp = stamp;
    return update;
  }

  static EntityUpdate pose_update(const std::string& id, Stamp stamp, Eigen::Vector3d position = {3.5, 1.7, 1.2}) {
    EntityUpdate update = bare_update(id, stamp);
    update.pose = PoseValue{position, Eigen::Quaterniond::Identity()};
    return update;
  }

  // The whole observable state: a rejected update must leave it exactly as it was.
  json snapshot() const {
    json state = json::object();
    for (const auto& [id, entity] : store_.entities()) state[id] = entity_to_json(entity);
    state["revision"] = store_.revision();
    return state;
  }

  void expect_rejected(const EntityUpdate& update, UpdateStatus status, const std::string& reason_part) {
    const json before = snapshot();
    const UpdateResult result = store_.apply(update);
    EXPECT_FALSE(result.accepted());
    EXPECT_EQ(result.status, status) << to_code(result.status) << ": " << result.reason;
    EXPECT_FALSE(result.change.has_value());
    EXPECT_NE(result.reason.find(reason_part), std::string::npos) << result.reason;
    EXPECT_EQ(snapshot(), before) << "a rejected update changed the store";
  }

  WorldStore store_;
};

TEST_F(WorldStoreTest, ConfigurationStateIsStampedWithTheLoadTime) {
  const Entity* robot = store_.find("robot");
  ASSERT_NE(robot, nullptr);
  EXPECT_EQ(robot->stamp, kLoadedAt);
  EXPECT_EQ(robot->pose->stamp, kLoadedAt);
  EXPECT_EQ(robot->source, "config:" + testing::fixture_cell_path());
  EXPECT_EQ(store_.revision(), 0u);
  EXPECT_EQ(store_.find("nope"), nullptr);
}

TEST_F(WorldStoreTest, AcceptsAPoseAndRecordsTheChange) {
  const Stamp stamp = kLoadedAt + seconds(5);
  EntityUpdate update = pose_update("load", stamp);
  update.quality = 0.8;
  const UpdateResult result = store_.apply(update);
  ASSERT_TRUE(result.accepted()) << result.reason;
  ASSERT_TRUE(result.change.has_value());
  const ChangeRecord& change = *result.change;
  EXPECT_EQ(change.revision, 1u);
  EXPECT_EQ(change.entity_id, "load");
  EXPECT_EQ(change.source, "vision_tracker");
  EXPECT_EQ(change.stamp, stamp);
  EXPECT_EQ(change.what(), "pose,quality,localized");
  EXPECT_TRUE(change.after.localized);

  const Entity* load = store_.find("load");
  EXPECT_TRUE(load->localized) << "a pose update localizes by default";
  EXPECT_EQ(load->stamp, stamp);
  EXPECT_EQ(load->source, "vision_tracker");
  EXPECT_EQ(load->pose->stamp, stamp);
  EXPECT_EQ(load->pose->source, "vision_tracker");
  EXPECT_EQ(load->pose->quality, 0.8);
  EXPECT_FALSE(load->pose->covariance.has_value());
  EXPECT_TRUE(load->pose->pose_parent_entity.translation().isApprox(Eigen::Vector3d(3.5, 1.7, 1.2)));
  EXPECT_EQ(store_.revision(), 1u);
  EXPECT_EQ(store_.apply(pose_update("load", stamp + seconds(1))).change->revision, 2u);
}

TEST_F(WorldStoreTest, AnEqualStampIsNotGoingBackwards) {
  const Stamp stamp = kLoadedAt + seconds(5);
  ASSERT_TRUE(store_.apply(pose_update("load", stamp)).accepted());
  EXPECT_TRUE(store_.apply(pose_update("load", stamp, {3.6, 1.7, 1.2})).accepted());
}

TEST_F(WorldStoreTest, AcceptsACovarianceAndReportsIt) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  Covariance6d covariance = Covariance6d::Identity() * 1e-4;
  covariance(0, 1) = covariance(1, 0) = 2e-5;
  update.covariance = covariance;
  const UpdateResult result = store_.apply(update);
  ASSERT_TRUE(result.accepted()) << result.reason;
  EXPECT_EQ(result.change->what(), "pose,covariance,localized");
  EXPECT_EQ(*store_.find("load")->pose->covariance, covariance);
  // The next pose without a covariance drops it: it described the previous estimate.
  const UpdateResult next = store_.apply(pose_update("load", kLoadedAt + seconds(2)));
  EXPECT_EQ(next.change->what(), "pose,covariance");
  EXPECT_FALSE(store_.find("load")->pose->covariance.has_value());
}

TEST_F(WorldStoreTest, NormalizesANearlyUnitQuaternion) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  update.pose->orientation = Eigen::Quaterniond(1.0 + 5e-7, 0, 0, 0);
  ASSERT_TRUE(store_.apply(update).accepted());
  EXPECT_NEAR(Eigen::Quaterniond(store_.find("load")->pose->pose_parent_entity.linear()).norm(), 1.0, 1e-15);
}

TEST_F(WorldStoreTest, ReparentsWithAPoseInTheNewParent) {
  // The robot reports the gripper, then the load is attached to the gripper.
  EntityUpdate gripper = pose_update("gripper", kLoadedAt + seconds(1), {0.5, 0.0, 0.3});
  gripper.source = "robot_driver";
  ASSERT_TRUE(store_.apply(gripper).accepted());
  EntityUpdate attach = pose_update("load", kLoadedAt + seconds(2), {0.0, 0.0, 0.32});
  attach.source = "AttachRobotToLoad";
  attach.parent = "gripper";
  const UpdateResult result = store_.apply(attach);
  ASSERT_TRUE(result.accepted()) << result.reason;
  EXPECT_EQ(result.change->what(), "parent,pose,localized");
  const auto in_robot = pose_in_frame(store_.entities(), "load", "robot");
  ASSERT_TRUE(in_robot.ok()) << in_robot.message;
  EXPECT_TRUE(in_robot.value.pose_frame_entity.translation().isApprox(Eigen::Vector3d(0.5, 0.0, 0.62)));
}

TEST_F(WorldStoreTest, LocalizedFlagAloneAndAttributesPatch) {
  ASSERT_TRUE(store_.apply(pose_update("load", kLoadedAt + seconds(1))).accepted());
  EntityUpdate unlocalize = bare_update("load", kLoadedAt + seconds(2), "Place");
  unlocalize.localized = false;
  unlocalize.attributes_patch = json{{"held_by", "gripper"}, {"note", "moved"}};
  const UpdateResult result = store_.apply(unlocalize);
  ASSERT_TRUE(result.accepted()) << result.reason;
  EXPECT_EQ(result.change->what(), "localized,attributes");
  const Entity* load = store_.find("load");
  EXPECT_FALSE(load->localized);
  EXPECT_EQ(load->pose->stamp, kLoadedAt + seconds(1)) << "the pose keeps its observation time";
  EXPECT_EQ(load->stamp, kLoadedAt + seconds(2));
  EXPECT_EQ(load->attributes["held_by"], "gripper");

  EntityUpdate remove = bare_update("load", kLoadedAt + seconds(3), "Place");
  remove.attributes_patch = json{{"held_by", nullptr}};  // RFC 7396: null removes
  ASSERT_TRUE(store_.apply(remove).accepted());
  EXPECT_FALSE(store_.find("load")->attributes.contains("held_by"));
  EXPECT_EQ(store_.find("load")->attributes["note"], "moved");
}

TEST_F(WorldStoreTest, ARootFrameAcceptsAttributesOnly) {
  EntityUpdate update = bare_update("world", kLoadedAt + seconds(1), "operator");
  update.attributes_patch = json{{"site", "hall 2"}};
  EXPECT_TRUE(store_.apply(update).accepted());
}

TEST_F(WorldStoreTest, RejectsAnUnknownEntity) {
  expect_rejected(pose_update("crate", kLoadedAt + seconds(1)), UpdateStatus::kUnknownEntity, "no entity \"crate\"");
}

TEST_F(WorldStoreTest, RejectsAMissingSource) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  update.source.clear();
  expect_rejected(update, UpdateStatus::kMissingSource, "source is empty");
}

TEST_F(WorldStoreTest, RejectsAMissingStamp) {
  expect_rejected(pose_update("load", Stamp{}), UpdateStatus::kMissingStamp, "not after the Unix epoch");
}

TEST_F(WorldStoreTest, RejectsTimeGoingBackwards) {
  // Older than the configuration's load time.
  expect_rejected(pose_update("load", kLoadedAt - milliseconds(1)), UpdateStatus::kStampBackwards,
                  "older than the last accepted change at 1000.000000000 s");
  // Older than the last accepted update, by one nanosecond.
  ASSERT_TRUE(store_.apply(pose_update("load", kLoadedAt + seconds(5))).accepted());
  expect_rejected(pose_update("load", kLoadedAt + seconds(5) - std::chrono::nanoseconds(1)), UpdateStatus::kStampBackwards,
                  "999999999 s is older");
  EXPECT_EQ(to_code(UpdateStatus::kStampBackwards), "STAMP_BACKWARDS");
}

TEST_F(WorldStoreTest, RejectsAnEmptyUpdate) {
  EntityUpdate update = bare_update("load", kLoadedAt + seconds(1), "x");
  expect_rejected(update, UpdateStatus::kEmptyUpdate, "changes nothing");
}

TEST_F(WorldStoreTest, RejectsAPoseOrParentForARootFrame) {
  expect_rejected(pose_update("world", kLoadedAt + seconds(1)), UpdateStatus::kRootFrame, "root frame");
  EntityUpdate localize = bare_update("world", kLoadedAt + seconds(1), "x");
  localize.localized = true;
  expect_rejected(localize, UpdateStatus::kRootFrame, "root frame");
}

TEST_F(WorldStoreTest, RejectsAnUnknownParent) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  update.parent = "shelf";
  expect_rejected(update, UpdateStatus::kUnknownParent, "parent \"shelf\" is not an entity");
}

TEST_F(WorldStoreTest, RejectsAFrameCycle) {
  EntityUpdate update = pose_update("robot", kLoadedAt + seconds(1));
  update.parent = "gripper";  // the gripper hangs on the robot
  expect_rejected(update, UpdateStatus::kFrameCycle, "descendants");
  update.parent = "robot";
  expect_rejected(update, UpdateStatus::kFrameCycle, "the entity itself");
}

TEST_F(WorldStoreTest, RejectsAParentWithoutPose) {
  EntityUpdate update = bare_update("load", kLoadedAt + seconds(1), "x");
  update.parent = "gripper";
  expect_rejected(update, UpdateStatus::kParentWithoutPose, "needs the pose in that parent");
}

TEST_F(WorldStoreTest, RejectsNaNAndInfinity) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1), {kNaN, 0, 0});
  expect_rejected(update, UpdateStatus::kNotFinite, "position is not finite");
  update = pose_update("load", kLoadedAt + seconds(1), {0, kInf, 0});
  expect_rejected(update, UpdateStatus::kNotFinite, "position is not finite");
  update = pose_update("load", kLoadedAt + seconds(1));
  update.pose->orientation = Eigen::Quaterniond(kNaN, 0, 0, 0);
  expect_rejected(update, UpdateStatus::kNotFinite, "orientation is not finite");
  update = pose_update("load", kLoadedAt + seconds(1));
  Covariance6d covariance = Covariance6d::Identity();
  covariance(2, 2) = kNaN;
  update.covariance = covariance;
  expect_rejected(update, UpdateStatus::kNotFinite, "covariance is not finite");
  update = pose_update("load", kLoadedAt + seconds(1));
  update.quality = kNaN;
  expect_rejected(update, UpdateStatus::kNotFinite, "quality is not finite");
  update = pose_update("load", kLoadedAt + seconds(1));
  update.attributes_patch = json{{"mass_kg", kInf}};
  expect_rejected(update, UpdateStatus::kNotFinite, "/attributes/mass_kg");
}

TEST_F(WorldStoreTest, RejectsANonUnitQuaternion) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  update.pose->orientation = Eigen::Quaterniond(1.01, 0, 0, 0);
  expect_rejected(update, UpdateStatus::kNonUnitQuaternion, "norm 1.01");
  update.pose->orientation = Eigen::Quaterniond(0, 0, 0, 0);
  expect_rejected(update, UpdateStatus::kNonUnitQuaternion, "norm 0");
}

TEST_F(WorldStoreTest, RejectsABadCovariance) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  Covariance6d covariance = Covariance6d::Identity();
  covariance(0, 3) = 0.5;  // not mirrored
  update.covariance = covariance;
  expect_rejected(update, UpdateStatus::kBadCovariance, "not symmetric");
  covariance = Covariance6d::Identity();
  covariance(4, 4) = -1e-6;
  update.covariance = covariance;
  expect_rejected(update, UpdateStatus::kBadCovariance, "negative variance");
}

TEST_F(WorldStoreTest, RejectsAQualityOutsideZeroToOne) {
  EntityUpdate update = pose_update("load", kLoadedAt + seconds(1));
  update.quality = 1.5;
  expect_rejected(update, UpdateStatus::kBadQuality, "outside [0, 1]");
  update.quality = -0.1;
  expect_rejected(update, UpdateStatus::kBadQuality, "outside [0, 1]");
}

TEST_F(WorldStoreTest, RejectsAnEstimateWithoutPose) {
  EntityUpdate update = bare_update("load", kLoadedAt + seconds(1), "x");
  update.quality = 0.5;
  expect_rejected(update, UpdateStatus::kEstimateWithoutPose, "none is given");
}

TEST_F(WorldStoreTest, RejectsLocalizedWithoutPose) {
  EntityUpdate update = bare_update("gripper", kLoadedAt + seconds(1), "x");  // no pose in the configuration
  update.localized = true;
  expect_rejected(update, UpdateStatus::kLocalizedWithoutPose, "has no pose");
}

TEST_F(WorldStoreTest, RejectsBadAttributes) {
  EntityUpdate update = bare_update("load", kLoadedAt + seconds(1), "x");
  update.attributes_patch = json::array({1, 2});
  expect_rejected(update, UpdateStatus::kBadAttributes, "must be a JSON object");
  json deep = json::object();
  json* cursor = &deep;
  for (int i = 0; i < 20; ++i) cursor = &((*cursor)["k"] = json::object());
  update.attributes_patch = deep;
  expect_rejected(update, UpdateStatus::kBadAttributes, "nested deeper than 16 levels");
}

TEST_F(WorldStoreTest, EveryStatusHasADistinctCode) {
  std::set<std::string_view> codes;
  for (int s = static_cast<int>(UpdateStatus::kAccepted); s <= static_cast<int>(UpdateStatus::kEstimateWithoutPose); ++s) {
    const auto code = to_code(static_cast<UpdateStatus>(s));
    EXPECT_NE(code, "UNKNOWN");
    EXPECT_TRUE(codes.insert(code).second) << code;
  }
}

}  // namespace
}  // namespace rigger::world
