// A PAUSE that holds motion, in physics: cell_sim (MuJoCo arm), the skill executor hosting
// MoveTo and the task controller as real processes on a private domain; the test submits the task and
// sends PAUSE / RESUME on rigger/task/command, and judges the arm by the simulator's own state stream
// (rigger/robot/state from cell_sim: the tool twist and pose of the physics model).
// - PAUSE mid-motion: the tool's speed falls below 1 mm/s within a bound and stays below it (and the
//   tool within 1 mm of where it stopped) for 2 s while paused; the task stays PAUSED, the leaf RUNNING;
// - RESUME (riggerctl resume, which prints what the leaf answered): the motion goes on to its goal and
//   the task SUCCEEDS, the tool within 5 mm of the goal;
// - the journal names who paused and resumed, and that MoveTo held and continued.
#include <algorithm>
#include <cstdio>

#include "cell_sim_test_support.hpp"
#include "controller_test_support.hpp"
#include "rigger/protocol/robot.hpp"

namespace rigger::testing::controller {
namespace {

using namespace std::chrono_literals;

constexpr const char* kExecutor = "robot-skills";
constexpr double kStillMps = 0.001;  // "holds still": below 1 mm/s

struct ToolSample {
  WallTime stamp{};
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double speed_mps = 0.0;
};

class PauseCellTest : public ControllerTest {
 protected:
  void SetUp() override {
    ControllerTest::SetUp();
    robot_ = std::make_unique<dds::Reader<rigger_robot_RobotState>>(cell_.participant(), protocol::robot::kState);
    cell_.loop().on_data(*robot_, [this] {
      robot_->take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        const auto twist = dds::to_domain(s.tool_twist);
        tool_.push_back({dds::to_domain(s.header.stamp), dds::to_domain(s.tool_pose), twist.head<3>().norm()});
      });
    });
    const std::string plc_port = std::to_string(free_tcp_port());
    cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", plc_port});
    const json executor = {{"executor_id", kExecutor}, {"skills", {"MoveTo"}}, {"gripper", false},
                           {"world_model", false},     {"crane", false},      {"tracker", false},
                           {"admittance", false},      {"operator", false}};
    cell_.start(kExecutor, "skill_executor", {"--id", kExecutor, "--config", write_config(kExecutor, executor)});
    start_controller();
    wait_ready({"cell_sim", kExecutor, "tc"});
    ASSERT_TRUE(cell_.wait_until([&] { return !tool_.empty(); }, 10s)) << "no robot state from cell_sim";
  }

  /// Waits (on samples) for one stamped at least `after`; false on `timeout`.
  bool wait_sample_after(WallTime after, std::chrono::milliseconds timeout) {
    return cell_.wait_until([&] { return !tool_.empty() && tool_.back().stamp >= after; }, timeout);
  }

  std::unique_ptr<dds::Reader<rigger_robot_RobotState>> robot_;
  std::vector<ToolSample> tool_;
};

TEST_F(PauseCellTest, APauseMidMotionHoldsTheArmStillAndResumeCompletesTheTask) {
  // MoveTo 15 cm up from where the tool is, at a tenth of the arm's speed (5 cm/s): about 3.5 s.
  const Eigen::Isometry3d start = tool_.back().pose;
  Eigen::Isometry3d goal = start;
  goal.translation().z() += 0.15;
  const Eigen::Quaterniond q(start.linear());
  const json recipe = {
      {"recipe_version", 1},
      {"task_id", "pause"},
      {"root",
       {{"type", "Skill"},
        {"skill", "MoveTo"},
        {"params",
         {{"goal",
           {{"position_m", {goal.translation().x(), goal.translation().y(), goal.translation().z()}},
            {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}}}},
          {"speed_scale", 0.1},
          {"timeout_s", 30.0}}}}}};
  submit("pause", recipe);

  // Mid-motion, at (nearly) its cruise speed of 5 cm/s.
  ASSERT_TRUE(cell_.wait_until([&] { return tool_.back().speed_mps > 0.04; }, 20s)) << cell_.logs();
  const double speed_before = tool_.back().speed_mps;
  const WallTime paused_at = std::chrono::system_clock::now();
  command("pause", rigger_task_TASK_PAUSE, "hold for the test");
  ASSERT_TRUE(wait_task("pause", rigger_task_TASK_PAUSED, 5s));

  // Below 1 mm/s within 1 s of the PAUSE (the target is 300 ms; measured and printed).
  const auto still = [&] {
    return std::find_if(tool_.begin(), tool_.end(), [&](const ToolSample& s) {
      return s.stamp >= paused_at && s.speed_mps < kStillMps;
    });
  };
  ASSERT_TRUE(cell_.wait_until([&] { return still() != tool_.end(); }, 3s)) << "the arm did not stop";
  const ToolSample first_still = *still();
  const double to_still_ms = std::chrono::duration<double, std::milli>(first_still.stamp - paused_at).count();
  std::printf("pause: tool at %.1f mm/s when paused, below 1 mm/s %.0f ms after the PAUSE\n", speed_before * 1000.0,
              to_still_ms);
  RecordProperty("pause_to_still_ms", std::to_string(to_still_ms));
  EXPECT_LT(to_still_ms, 1000.0);

  // It stays still for 2 s while paused: every sample below 1 mm/s, the tool within 1 mm of where it
  // stopped, the goal not reached.
  const std::size_t from = static_cast<std::size_t>(still() - tool_.begin());
  ASSERT_TRUE(wait_sample_after(first_still.stamp + 2s, 5s));
  double max_speed = 0.0, max_drift = 0.0;
  std::size_t samples = 0;
  for (std::size_t i = from; i < tool_.size() && tool_[i].stamp <= first_still.stamp + 2s; ++i, ++samples) {
    max_speed = std::max(max_speed, tool_[i].speed_mps);
    max_drift = std::max(max_drift, (tool_[i].pose.translation() - first_still.pose.translation()).norm());
  }
  std::printf("pause: held %zu samples over 2 s: max speed %.3f mm/s, max drift %.3f mm\n", samples,
              max_speed * 1000.0, max_drift * 1000.0);
  EXPECT_GE(samples, 50u) << "too few robot states to judge (100 Hz expected)";
  EXPECT_LT(max_speed, kStillMps);
  EXPECT_LT(max_drift, 0.001);
  EXPECT_GT((goal.translation() - first_still.pose.translation()).norm(), 0.02) << "it stopped at the goal";
  EXPECT_FALSE(finished("pause"));
  EXPECT_EQ(node_at("pause", "root", rigger_task_NODE_SUCCESS), nullptr);

  // RESUME through riggerctl, which waits for RUNNING and prints what the leaf answered.
  const CtlResult resumed = ctl("resume", {"resume", "pause"});
  EXPECT_EQ(resumed.code(), 0) << resumed.output;
  EXPECT_NE(resumed.output.find("  root: MoveTo continues in state move"), std::string::npos)
      << resumed.output;
  ASSERT_TRUE(wait_finished("pause", 30s)) << cell_.logs();
  EXPECT_EQ(last("pause").state, rigger_task_TASK_SUCCEEDED) << last("pause").code << ": " << last("pause").message;
  const double error_m = (tool_.back().pose.translation() - goal.translation()).norm();
  std::printf("pause: resumed, task SUCCEEDED, tool %.2f mm from the goal\n", error_m * 1000.0);
  EXPECT_LT(error_m, 0.005);

  // The journal says who paused and resumed, and what the leaf did.
  const auto lines = journal("pause");
  const auto line = [&](const std::string& node, const std::string& kind, const std::string& code) -> std::string {
    for (const auto& l : lines)
      if (l.node == node && l.kind == kind && l.code == code) return l.message;
    return "<none>";
  };
  EXPECT_NE(line("", "COMMAND", "PAUSE").find("test"), std::string::npos) << line("", "COMMAND", "PAUSE");
  EXPECT_NE(line("", "COMMAND", "RESUME").find("riggerctl:"), std::string::npos) << line("", "COMMAND", "RESUME");
  EXPECT_NE(line("root", "EVENT", "PAUSED").find("MoveTo holds still in state move"), std::string::npos)
      << line("root", "EVENT", "PAUSED");
  EXPECT_NE(line("root", "EVENT", "RESUMED").find("MoveTo continues"), std::string::npos)
      << line("root", "EVENT", "RESUMED");
}

}  // namespace
}  // namespace rigger::testing::controller
