// The 3D cell's feed: world poses through the chain of parents, the tool and the hook in their devices'
// frames, and only what moved. (The picture at a replay's moment: web/test/cell_picture.test.mjs.)
#include "cell_feed.hpp"

#include <gtest/gtest.h>

namespace rigger::console {
namespace {

using nlohmann::json;

Eigen::Isometry3d at(double x, double y, double z, double yaw_deg = 0) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  p.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return p;
}

void expect_position(const json& p, double x, double y, double z) {
  ASSERT_TRUE(p.is_array() && p.size() == 3) << p.dump();
  EXPECT_NEAR(p[0].get<double>(), x, 1e-4);
  EXPECT_NEAR(p[1].get<double>(), y, 1e-4);
  EXPECT_NEAR(p[2].get<double>(), z, 1e-4);
}

TEST(CellFeedTest, ObjectsToolAndHookInTheWorldFrame) {
  CellFeed feed;
  feed.entity("world", "frame", "", std::nullopt);
  feed.entity("robot", "device", "world", at(2.0, 1.0, 0.5, 90));
  feed.entity("crane", "device", "world", at(0, 0, 0));
  feed.entity("table", "object", "world", at(1, 1, 0.5));
  feed.entity("part", "object", "table", at(0.1, 0, 0.2, 90));  // on the table, turned
  feed.entity("unknown", "object", "world", std::nullopt);      // no pose yet: left out
  feed.entity("lost", "object", "nowhere_frame", at(1, 0, 0));  // a parent no entity names: the world
  feed.tool("robot", Eigen::Vector3d(0.5, 0, 0.3));
  feed.hook("crane", Eigen::Vector3d(3, 2, 4));
  const auto change = feed.take_changes(100.0);
  ASSERT_TRUE(change);
  const json& objects = change->at("objects");
  EXPECT_EQ(objects.size(), 3u) << change->dump();  // table, part, lost; never the devices
  EXPECT_FALSE(objects.contains("unknown"));
  expect_position(objects["part"]["position_m"], 1.1, 1.0, 0.7);
  const json q = objects["part"]["quaternion_xyzw"];
  EXPECT_NEAR(q[2].get<double>(), std::sqrt(0.5), 1e-4);
  expect_position(objects["lost"]["position_m"], 1, 0, 0);
  expect_position(change->at("tool"), 2.0, 1.5, 0.8);  // the base turned 90° about z
  expect_position(change->at("hook"), 3, 2, 4);
  EXPECT_DOUBLE_EQ(change->at("t").get<double>(), 100.0);
  EXPECT_FALSE(feed.take_changes(100.1)) << "nothing came: nothing to send";
}

TEST(CellFeedTest, OnlyWhatMovedIsSentAgain) {
  CellFeed feed;
  feed.entity("a", "object", "world", at(1, 0, 0));
  feed.entity("b", "object", "world", at(2, 0, 0));
  feed.hook("", Eigen::Vector3d(0, 0, 4));
  ASSERT_TRUE(feed.take_changes(1.0));
  feed.entity("a", "object", "world", at(1.0003, 0, 0));  // 0.3 mm: not sent
  feed.hook("", Eigen::Vector3d(0, 0, 4.0001));
  EXPECT_FALSE(feed.take_changes(1.1));
  feed.entity("a", "object", "world", at(1.0006, 0, 0));  // 0.6 mm from what was sent
  feed.entity("b", "object", "world", at(2, 0, 0, 0.2));  // turned 0.2°
  const auto change = feed.take_changes(1.2);
  ASSERT_TRUE(change);
  EXPECT_EQ(change->at("objects").size(), 2u) << change->dump();
  EXPECT_FALSE(change->contains("hook"));
  // A parent that moves moves what it carries.
  feed.entity("c", "object", "a", at(0, 0, 1));
  ASSERT_TRUE(feed.take_changes(1.3));
  feed.entity("a", "object", "world", at(1.5, 0, 0));
  const auto carried = feed.take_changes(1.4);
  ASSERT_TRUE(carried);
  expect_position(carried->at("objects")["c"]["position_m"], 1.5, 0, 1);
}

TEST(CellFeedTest, ALoopOfParentsIsNotAPose) {
  CellFeed feed;
  feed.entity("a", "object", "b", at(1, 0, 0));
  feed.entity("b", "object", "a", at(1, 0, 0));
  EXPECT_FALSE(feed.take_changes(1.0));
}

}  // namespace
}  // namespace rigger::console
