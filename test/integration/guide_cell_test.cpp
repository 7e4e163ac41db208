// CollaborativeMoveLoad in physics: recipes/examples/guide_by_joystick.json on every real process
// of the cell. The robot localizes the load and attaches itself to it; then the operator's joystick
// (`riggerctl jog --script`, the real tool, publishing rigger/operator/joystick) drives admittance control of
// robot and crane, and the scripted operator answers the skill's 'done' prompt afterwards. The test asserts
// from the physics' ground truth (rigger/sim/ground_truth) that the crane-carried load ends where the
// joystick pushed it, within 5 mm.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "rigger/protocol/operator.hpp"
#include "scenario_support.hpp"
#include "world_query_support.hpp"

namespace rigger::testing::scenario {
namespace {

constexpr auto kTaskTimeout = std::chrono::minutes(4);
constexpr double kJogSpeedMps = 0.05;
constexpr double kJogSeconds = 4.0;
// admittance_control applies a joystick sample until it is this old (deploy/config/admittance_control.json,
// robot.reference_timeout_s).
constexpr double kReferenceTimeoutS = 0.2;

/// A velocity command as the test read it off the wire (the joystick's, or admittance control's twist to
/// the robot).
struct VelocitySample {
  WallTime stamp;
  double x_mps;   ///< along the robot base frame's x
  double hold_s;  ///< how long after its stamp its reader applies it at most, without a newer one
};

/// How far velocity commands move a plant along x: each sample's velocity for as long as it is applied
/// (until the next one, at most its hold_s), in the plant's own time. For the joystick, with a plant in
/// real time, that is the script's 0.05 m/s × 4 s; a simulator that fell behind real time and skipped
/// ahead moved for less, and no controller could have made up for it. `fallbacks` counts the samples
/// whose simulated time was not known (wall time used).
double distance_in_plant_time(const std::vector<VelocitySample>& samples, const ScenarioCell& s, int& fallbacks) {
  double distance = 0.0;
  for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
    const WallTime from = samples[i].stamp;
    const double wall_s =
        std::min(samples[i].hold_s, std::chrono::duration<double>(samples[i + 1].stamp - from).count());
    const WallTime to = from + std::chrono::duration_cast<WallTime::duration>(std::chrono::duration<double>(wall_s));
    const auto sim_from = s.sim_time_at(from), sim_to = s.sim_time_at(to);
    double plant_s = wall_s;
    if (sim_from && sim_to)
      plant_s = *sim_to - *sim_from;
    else
      ++fallbacks;
    distance += samples[i].x_mps * plant_s;
  }
  return distance;
}

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
  // What the joystick commanded, and what admittance control commanded the robot (base frame).
  std::vector<VelocitySample> joystick, twists;
  dds::Reader<rigger_sensing_TwistCommand> joystick_reader(cell_.participant(), protocol::operator_ui::kJoystick,
                                                           dds::qos::setpoints().keep_last(256));
  dds::Reader<rigger_sensing_TwistCommand> twist_reader(cell_.participant(), protocol::robot::kCmdTwist,
                                                        dds::qos::setpoints().keep_last(1024));
  cell_.loop().on_data(joystick_reader, [&] {
    joystick_reader.take([&](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
      joystick.push_back({dds::to_domain(t.header.stamp), t.twist.linear.x, kReferenceTimeoutS});
    });
  });
  cell_.loop().on_data(twist_reader, [&] {
    twist_reader.take([&](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
      twists.push_back({dds::to_domain(t.header.stamp), t.twist.linear.x, t.timeout_s});
    });
  });
  const Eigen::Vector3d crane_before = s.crane_position();
  // Still for 3 s (the skill takes the crane and engages admittance meanwhile), then +x for 4 s, then zero.
  auto jog = start_riggerctl(
      cell_, "jog",
      {"jog", "--script", "stop:3s,x+" + std::to_string(kJogSpeedMps) + ":" + std::to_string(kJogSeconds) + "s"});
  ASSERT_TRUE(cell_.wait_until([&] { return !jog->running(); }, 30s)) << "the jog script did not end";
  const auto jog_status = jog->wait(1s);
  ASSERT_TRUE(jog_status && jog_status->exited && jog_status->code == 0) << jog->log();
  const Eigen::Vector3d after_jog = s.truth("load")->translation();

  ASSERT_TRUE(s.wait_node("guide load", rigger_task_NODE_SUCCESS, 30s)) << s.task_summary();
  const Eigen::Vector3d at_done = s.truth("load")->translation();
  const Eigen::Vector3d crane_travel = s.crane_position() - crane_before;
  ASSERT_TRUE(s.wait_task_end(kTaskTimeout)) << "the task did not end in time: " << s.task_summary();
  std::printf("--- %s: task %s after %.1f s\n%s", recipe.c_str(), s.task_code().c_str(), s.task_seconds(),
              s.durations().c_str());
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();

  int fallbacks = 0;
  const double commanded = distance_in_plant_time(joystick, s, fallbacks);
  int twist_fallbacks = 0;
  const double twist_x_m = distance_in_plant_time(twists, s, twist_fallbacks);
  const Eigen::Vector3d moved = after_jog - before;
  const double along = moved.dot(pushed);
  const double across = (moved - along * pushed).norm();
  const double drift = (at_done - after_jog).norm();
  const double along_at_done = (at_done - before).dot(pushed);
  std::printf(
      "  load moved %.1f mm along the joystick's +x by the jog's end (the script: %.0f mm; its %zu samples "
      "in the physics' time: %.1f mm, %d of them timed by the wall clock), %.1f mm across it; %.1f mm more "
      "until 'done', %.1f mm in all\n",
      along * 1000.0, kJogSpeedMps * kJogSeconds * 1000.0, joystick.size(), commanded * 1000.0, fallbacks,
      across * 1000.0, drift * 1000.0, along_at_done * 1000.0);
  std::printf(
      "  until 'done': admittance's %zu twists to the robot add up to %.1f mm along its x in the physics' time "
      "(%d timed by the wall clock); the crane's axes moved (%.1f, %.1f, %.1f) mm\n",
      twists.size(), twist_x_m * 1000.0, twist_fallbacks, crane_travel.x() * 1000.0, crane_travel.y() * 1000.0,
      crane_travel.z() * 1000.0);
  ASSERT_GT(joystick.size(), 100U) << "the test did not read the joystick's samples";
  ASSERT_GT(commanded, 0.75 * kJogSpeedMps * kJogSeconds) << "the joystick or the physics lost much of the jog";
  // Where the joystick put it, once robot and crane came to rest: what it commanded, within 5 mm.
  EXPECT_NEAR(along_at_done, commanded, 0.005) << "the load is not where the joystick put it";
  EXPECT_LT((at_done - before - along_at_done * pushed).norm(), 0.005) << "the load went sideways";
  EXPECT_EQ(s.gripper_energized(), !releases)
      << (releases ? "the robot should have let go" : "the load must stay held");
  // The load moved where no camera saw it: CollaborativeMoveLoad told the world model.
  const auto localized = world.localized("load");
  ASSERT_TRUE(localized.has_value()) << "the world model did not answer";
  EXPECT_FALSE(*localized) << "the world model still says the load is where it was localized";
}

}  // namespace
}  // namespace rigger::testing::scenario
