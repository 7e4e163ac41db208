// A Condition reads the world model: the controller and world_model as real processes; the test
// changes the world through rigger/world/update (WorldClient) and runs a recipe whose only node is
// Condition ObjectLocalized(load, max_age_s) before, right after and long after the load was seen.
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "controller_test_support.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/world_client/world_client.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing::controller {
namespace {

constexpr double kMaxAgeS = 1.5;

json condition_recipe(const std::string& task_id) {
  return {{"recipe_version", 1},
          {"task_id", task_id},
          {"root",
           {{"type", "Condition"},
            {"name", "load seen lately"},
            {"condition", "ObjectLocalized"},
            {"params", {{"object", "load"}, {"max_age_s", kMaxAgeS}}}}}};
}

class ControllerWorldTest : public ControllerTest {
 protected:
  void SetUp() override {
    ControllerTest::SetUp();
    cell_.start("wm", "world_model", {"--id", "wm", "--db", cell_.log_dir() + "/world.sqlite"});
    start_controller();
    wait_ready({"wm", "tc"});
    world_ = std::make_unique<world_client::WorldClient>(cell_.participant(), cell_.loop(), null_logger(), "test");
    ASSERT_TRUE(cell_.wait_until([&] { return world_->connected(); }, 10s));
  }

  /// Runs the condition recipe as `task_id` to its end.
  const TaskSeen& check(const std::string& task_id) {
    submit(task_id, condition_recipe(task_id));
    EXPECT_TRUE(wait_finished(task_id)) << task_id;
    return last(task_id);
  }

  std::unique_ptr<world_client::WorldClient> world_;
};

TEST_F(ControllerWorldTest, ObjectLocalizedFailsBeforePassesAfterAndFailsWhenThePoseIsTooOld) {
  // Before anyone saw the load.
  const TaskSeen& before = check("before");
  EXPECT_EQ(before.state, rigger_task_TASK_FAILED);
  // The cell file knows the load but nobody has seen it yet (NO_POSE when it has no pose at all).
  EXPECT_TRUE(before.code == "NOT_LOCALIZED" || before.code == "NO_POSE") << before.code << " " << before.message;
  EXPECT_EQ(before.failed_node, "root");

  // The camera localizes it.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(3.4, 1.8, 1.25);
  const auto seen_at = std::chrono::system_clock::now();
  const auto seen_steady = Clock::now();
  std::optional<world_client::Reply> updated;
  world_->update_pose("load", "world", pose, seen_at, 0.9, true, 5s,
                      [&](const world_client::Reply& r) { updated = r; });
  ASSERT_TRUE(cell_.wait_until([&] { return updated.has_value(); }, 10s));
  ASSERT_TRUE(updated->ok) << updated->code << ": " << updated->message;

  const TaskSeen& after = check("after");
  RIGGER_REQUIRE_OR_SKIP(Clock::now() - seen_steady < std::chrono::duration<double>(kMaxAgeS),
                         "the machine took longer than max_age_s to answer; freshness cannot be judged");
  EXPECT_EQ(after.state, rigger_task_TASK_SUCCEEDED) << after.code << " " << after.message;
  const NodeSeen* passed = node_at("after", "root", rigger_task_NODE_SUCCESS);
  ASSERT_NE(passed, nullptr);
  EXPECT_NE(passed->message.find("ObjectLocalized(load"), std::string::npos) << passed->message;

  // Nobody sees the load again: once its pose is older than max_age_s the condition fails. The loop
  // runs until that moment (a timer wakes it), then the recipe runs again.
  bool aged = false;
  const auto wake = cell_.loop().after(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(kMaxAgeS) + 100ms),
      [&] { aged = true; });
  ASSERT_TRUE(cell_.wait_until([&] { return aged; }, 10s));
  cell_.loop().cancel(wake);
  const TaskSeen& stale = check("stale");
  EXPECT_EQ(stale.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(stale.code, "TOO_OLD") << stale.message;
  EXPECT_NE(stale.message.find("more than the"), std::string::npos) << stale.message;

  // Seen again: passes again.
  updated.reset();
  world_->update_pose("load", "world", pose, std::chrono::system_clock::now(), 0.9, true, 5s,
                      [&](const world_client::Reply& r) { updated = r; });
  ASSERT_TRUE(cell_.wait_until([&] { return updated.has_value(); }, 10s));
  ASSERT_TRUE(updated->ok) << updated->code;
  EXPECT_EQ(check("again").state, rigger_task_TASK_SUCCEEDED) << last("again").message;

  // The journal has the condition's verdicts.
  EXPECT_TRUE(has_line(journal("stale"), "root", "NODE", "FAILURE"));
}

}  // namespace
}  // namespace rigger::testing::controller
