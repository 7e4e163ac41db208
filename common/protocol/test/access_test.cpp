#include "rigger/protocol/access.hpp"

#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "rigger/protocol/catalog.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/safety.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::protocol {
namespace {

bool has(const std::vector<std::string>& v, const std::string& name) {
  return std::find(v.begin(), v.end(), name) != v.end();
}

std::set<std::string> writers_of(const char* topic) {
  std::set<std::string> ids;
  for (const auto& g : access_table())
    if (has(g.publish, topic)) ids.insert(g.identity);
  return ids;
}

TEST(AccessTable, EveryGrantNamesCatalogTopicsOnly) {
  std::set<std::string> identities;
  for (const auto& g : access_table()) {
    EXPECT_TRUE(identities.insert(g.identity).second) << "identity twice: " << g.identity;
    EXPECT_FALSE(g.description.empty()) << g.identity;
    for (const auto* list : {&g.publish, &g.subscribe})
      for (const auto& t : *list) EXPECT_NE(find_topic(t), nullptr) << g.identity << ": not a topic: " << t;
  }
  EXPECT_NE(find_grant("task_controller"), nullptr);
  EXPECT_EQ(find_grant("nobody"), nullptr);
}

TEST(AccessTable, EveryTopicHasAWriterAndAReader) {
  for (const auto& t : catalog()) {
    bool written = false, read = false;
    for (const auto& g : access_table()) {
      written = written || has(g.publish, t.name);
      read = read || has(g.subscribe, t.name);
    }
    EXPECT_TRUE(written) << t.name << ": no identity may write it (add it to common/protocol/src/access.cpp)";
    EXPECT_TRUE(read) << t.name << ": no identity may read it";
  }
}

// Cell revisions: proposed by the user tools (the programmer's identities) and the robot's executor (CalibrateCamera
// writes the camera's pose), not by the other executors; published by the world model only, read by every reader
// of the cell file.
TEST(AccessTable, OnlyTheUserToolsAndTheCalibrationProposeCellRevisions) {
  EXPECT_EQ(writers_of(world::kCellRequest.name), (std::set<std::string>{"console", "riggerctl", "robot-skills"}));
  EXPECT_EQ(writers_of(world::kCell.name), std::set<std::string>{"world_model"});
  EXPECT_EQ(writers_of(world::kCellReply.name), std::set<std::string>{"world_model"});
  for (const char* reader : {"cell_sim", "vision_tracker", "admittance_control", "cad", "console"})
    EXPECT_TRUE(has(find_grant(reader)->subscribe, world::kCell.name)) << reader;
  EXPECT_TRUE(has(find_grant("world_model")->subscribe, skill::kExecutors.name));
  // The console's 3D cell reads where the world model has every entity.
  EXPECT_TRUE(has(find_grant("console")->subscribe, world::kEntity.name));
}

// The access rules of DDS Security (docs/security.md): who may move things and who may start or stop a task.
TEST(AccessTable, OnlyTheUserToolsCommandTasks) {
  const std::set<std::string> tools{"console", "riggerctl"};
  EXPECT_EQ(writers_of(task::kRecipe.name), tools);
  EXPECT_EQ(writers_of(task::kCommand.name), tools);
  EXPECT_EQ(writers_of(operator_ui::kResponse.name),
            (std::set<std::string>{"console", "riggerctl", "scripted_operator"}));
}

TEST(AccessTable, OnlyAdmittanceAndSkillsCommandTheRobotAndTheCrane) {
  EXPECT_EQ(writers_of(crane::kCmdVelocity.name), std::set<std::string>{"admittance_control"});
  EXPECT_EQ(writers_of(robot::kCmdTwist.name), std::set<std::string>{"admittance_control"});
  EXPECT_EQ(writers_of(robot::kCmdMotion.name), std::set<std::string>{"robot-skills"});
  // riggerctl only for `crane reset`, which acknowledges a latched PLC fault and moves nothing.
  EXPECT_EQ(writers_of(crane::kControl.name),
            (std::set<std::string>{"admittance_control", "robot-skills", "riggerctl"}));
  EXPECT_EQ(writers_of(skill::kCommand.name), std::set<std::string>{"task_controller"});
}

// A real robot behind the ROS 2 bridge: the bridge is the robot's wrench and image source and the reader of the
// twist stream (and the robot's safe stop, which it obeys), nothing else of rigger's; its rt/ topics come from the cell
// (deploy/security/ros2.grants).
TEST(AccessTable, TheRos2BridgeCarriesOnlyTheWrenchJointStatesAndCameraInAndTheTwistOut) {
  const auto* bridge = find_grant("ros2_bridge");
  ASSERT_NE(bridge, nullptr);
  EXPECT_EQ(bridge->publish,
            (std::vector<std::string>{vision::kCameraImage.name, vision::kCameraInfo.name, robot::kState.name,
                                      robot::kWrench.name, system::kServiceState.name}));
  EXPECT_EQ(bridge->subscribe,
            (std::vector<std::string>{robot::kCmdTwist.name, safety::kStop.name, system::kServiceState.name}));
}

TEST(AccessTable, ObserverWritesNothingButItsAnnouncement) {
  const auto* observer = find_grant("observer");
  ASSERT_NE(observer, nullptr);
  EXPECT_EQ(observer->publish.size(), 1u);
  EXPECT_EQ(observer->subscribe.size(), catalog().size());
}

TEST(AccessTable, LinesForMakePki) {
  const auto lines = access_table_lines();
  EXPECT_NE(lines.find(std::string("task_controller subscribe ") + task::kRecipe.name + "\n"), std::string::npos);
  EXPECT_EQ(lines.find(std::string("vision_tracker publish ") + task::kRecipe.name), std::string::npos);
}

}  // namespace
}  // namespace rigger::protocol
