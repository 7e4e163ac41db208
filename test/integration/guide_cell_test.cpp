// CollaborativeMoveLoad in physics (issue 18): recipes/examples/guide_by_joystick.json on every real process
// of the cell. The robot localizes the load and attaches itself to it; then the operator's joystick
// (`riggerctl jog --script`, the real tool, publishing rigger/operator/joystick) drives admittance control of
// robot and crane, and the scripted operator answers the skill's 'done' prompt afterwards. The test asserts
// from the physics' ground truth (rigger/sim/ground_truth) that the crane-carried load ends where the
// joystick pushed it, within 5 mm.
#include <cmath>
#include <string>
#include <vector>

#include "scenario_support.hpp"
#include "world_query_support.hpp"

namespace rigger::testing::scenario {
namespace {

constexpr auto kTaskTimeout = std::chrono::minutes(4);
constexpr double kJogSpeedMps = 0.05;
constexpr double kJogSeconds = 4.0;

class GuideCellTest : public MultiProcessTest {
 protected:
  /// Runs `recipe`, whose CollaborativeMoveLoad is named "guide load", with the joystick scripted; `rules`
  /// are the scripted operator's extra answers; `releases`: the recipe lets go of the load at its end.
  void guide(const std::string& recipe, std::vector<std::string> rules, bool releases);
};

TEST_F(GuideCellTest, TheLoadFollowsTheOperatorsJoystickThroughRobotAndCrane) {
  guide("recipes/examples/guide_by_joystick.json", {}, true);
}

// The paper's OperatorDecision: the operator chooses "joystick" and guides the load.
TEST_F(GuideCellTest, TheOperatorChoosesTheJoystickAndGuidesTheLoad) {
  guide("recipes/examples/operator_choice.json", {"decision:joystick@0.5"}, false);
}

void GuideCellTest::guide(const std::string& recipe, std::vector<std::string> rules, bool releases) {
  // The 'done' comes 12 s after the prompt: long after the jog script (3 s still, 4 s moving) has ended.
  rules.insert(rules.begin(), "confirm:object=load:done@12");
  ScenarioCell s(cell_, rules);
  WorldQuery world(cell_);
  ASSERT_TRUE(s.ready()) << "not every service came up";
  const cell::CellFile cell = cell::load_cell_file(repo_file("deploy/cell/simulated_cell.json"));
  // The joystick's frame is the robot base frame (riggerctl jog): +x there, in the world.
  const Eigen::Vector3d pushed = cell.pose_root_entity("robot").linear().col(0);

  ASSERT_TRUE(s.submit(recipe));
  ASSERT_TRUE(s.wait_node("guide load", rigger_task_NODE_RUNNING, kTaskTimeout)) << s.task_summary();
  ASSERT_NE(s.node("guide load"), nullptr) << "the task ended before the guided move: " << s.task_summary();
  ASSERT_EQ(s.node("guide load")->state, rigger_task_NODE_RUNNING) << s.task_summary();
  const Eigen::Vector3d before = s.truth("load")->translation();
  // Still for 3 s (the skill takes the crane and engages admittance meanwhile), then +x for 4 s, then zero.
  auto jog = start_riggerctl(cell_, "jog",
                             {"jog", "--script", "stop:3s,x+" + std::to_string(kJogSpeedMps) + ":" +
                                                     std::to_string(kJogSeconds) + "s"});
  ASSERT_TRUE(cell_.wait_until([&] { return !jog->running(); }, 30s)) << "the jog script did not end";
  const auto jog_status = jog->wait(1s);
  ASSERT_TRUE(jog_status && jog_status->exited && jog_status->code == 0) << jog->log();
  const Eigen::Vector3d after_jog = s.truth("load")->translation();

  ASSERT_TRUE(s.wait_node("guide load", rigger_task_NODE_SUCCESS, 30s)) << s.task_summary();
  const Eigen::Vector3d at_done = s.truth("load")->translation();
  ASSERT_TRUE(s.wait_task_end(kTaskTimeout)) << "the task did not end in time: " << s.task_summary();
  std::printf("--- %s: task %s after %.1f s\n%s", recipe.c_str(), s.task_code().c_str(), s.task_seconds(),
              s.durations().c_str());
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();

  const Eigen::Vector3d moved = after_jog - before;
  const double along = moved.dot(pushed);
  const double across = (moved - along * pushed).norm();
  const double drift = (at_done - after_jog).norm();
  const double along_at_done = (at_done - before).dot(pushed);
  std::printf("  load moved %.1f mm along the joystick's +x by the jog's end (commanded %.0f mm), %.1f mm across "
              "it; %.1f mm more until 'done', %.1f mm in all\n",
              along * 1000.0, kJogSpeedMps * kJogSeconds * 1000.0, across * 1000.0, drift * 1000.0,
              along_at_done * 1000.0);
  // Where the joystick put it, once robot and crane came to rest: the commanded 0.05 m/s × 4 s within 5 mm.
  EXPECT_NEAR(along_at_done, kJogSpeedMps * kJogSeconds, 0.005) << "the load is not where the joystick put it";
  EXPECT_LT((at_done - before - along_at_done * pushed).norm(), 0.005) << "the load went sideways";
  EXPECT_EQ(s.gripper_energized(), !releases) << (releases ? "the robot should have let go" : "the load must stay held");
  // The load moved where no camera saw it: CollaborativeMoveLoad told the world model.
  const auto localized = world.localized("load");
  ASSERT_TRUE(localized.has_value()) << "the world model did not answer";
  EXPECT_FALSE(*localized) << "the world model still says the load is where it was localized";
}

}  // namespace
}  // namespace rigger::testing::scenario
