// A real ForceMonitor fails a Parallel through the controller: task_controller, a scripted executor
// (the skill) and monitor_host (the monitor) as real processes; the test is the robot's force sensor,
// publishing rigger/robot/wrench (sensing::WrenchStamped).
#include <string>

#include <gtest/gtest.h>

#include "controller_test_support.hpp"
#include "rigger/protocol/robot.hpp"

namespace rigger::testing::controller {
namespace {

class ControllerMonitorTest : public ControllerTest {
 protected:
  void SetUp() override {
    ControllerTest::SetUp();
    wrench_ =
        std::make_unique<dds::Writer<rigger_sensing_WrenchStamped>>(cell_.participant(), protocol::robot::kWrench);
    start_controller();
    // The skill runs until shut down and takes 0.2 s to stop (a robot braking).
    start_scripted("exec", {"Localize"}, json::object(), {{"Localize", {{"mode", "run"}, {"stop_delay_s", 0.2}}}});
    cell_.start("mh", "monitor_host", {"--id", "mh"});
    wait_ready({"tc", "exec", "mh"});
    ASSERT_TRUE(wrench_->wait_for_readers(1, 10s));
  }
  void TearDown() override {
    if (stream_ != 0) cell_.loop().cancel(stream_);
    ControllerTest::TearDown();
  }

  /// Publishes force_n_ along z every 5 ms, stamped now (as the robot driver does).
  void start_stream() {
    stream_ = cell_.loop().every(5ms, [this] {
      rigger_sensing_WrenchStamped w{};
      const std::string frame = "ft_sensor";
      w.header.stamp = dds::wire_now();
      w.header.frame_id = dds::wire_string(frame);
      w.wrench.force.z = force_n_;
      wrench_->write(w);
      ++samples_;
    });
  }

  std::unique_ptr<dds::Writer<rigger_sensing_WrenchStamped>> wrench_;
  dds::EventLoop::TimerId stream_ = 0;
  double force_n_ = 0.0;
  std::uint64_t samples_ = 0;
};

TEST_F(ControllerMonitorTest, AForceAboveTheLimitFailsTheParallelWithTheMonitorsCodeAfterTheSkillStopped) {
  force_n_ = 5.0;
  start_stream();
  const json recipe = {{"recipe_version", 1},
                       {"task_id", "force"},
                       {"root",
                        {{"type", "Parallel"},
                         {"name", "localize under force watch"},
                         {"success_threshold", 1},
                         {"failure_threshold", 1},
                         {"children",
                          {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
                           {{"type", "Monitor"}, {"monitor", "ForceMonitor"}, {"params", {{"max_force_n", 50.0}}}}}}}}};
  submit("force", recipe);
  ASSERT_TRUE(wait_command("force", "root/0", rigger_skill_SKILL_START));
  ASSERT_TRUE(wait_command("force", "root/1", rigger_skill_SKILL_START));
  EXPECT_EQ(command_at("force", "root/1", rigger_skill_SKILL_START)->executor, "mh");
  EXPECT_EQ(command_at("force", "root/0", rigger_skill_SKILL_START)->executor, "exec");
  // Below the limit for 100 samples: the monitor stays quiet and the task keeps running.
  const auto target = samples_ + 100;
  ASSERT_TRUE(cell_.wait_until([&] { return samples_ >= target; }, 10s));
  EXPECT_FALSE(finished("force")) << last("force").code << " " << last("force").message;
  EXPECT_EQ(event_at("force", "root/1", rigger_skill_SKILL_EVENT_FAILURE), nullptr);

  force_n_ = 120.0;  // contact
  ASSERT_TRUE(wait_finished("force"));
  const TaskSeen& s = last("force");
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "FORCE_LIMIT") << s.message;
  EXPECT_EQ(s.failed_node, "root/1");
  // The monitor fired (FAILURE from monitor_host), the skill was shut down and answered STOPPED, and only
  // then did the Parallel (and the task) fail.
  const EventSeen* fired = event_at("force", "root/1", rigger_skill_SKILL_EVENT_FAILURE);
  ASSERT_NE(fired, nullptr);
  EXPECT_EQ(fired->executor, "mh");
  EXPECT_EQ(fired->code, "FORCE_LIMIT");
  const CommandSeen* shutdown = command_at("force", "root/0", rigger_skill_SKILL_SHUTDOWN);
  ASSERT_NE(shutdown, nullptr);
  const EventSeen* stopped = event_at("force", "root/0", rigger_skill_SKILL_EVENT_STOPPED);
  ASSERT_NE(stopped, nullptr);
  EXPECT_LE(stopped->at, s.at);
  const NodeSeen* skill_stopped = node_at("force", "root/0", rigger_task_NODE_STOPPED);
  const NodeSeen* parallel_failed = node_at("force", "root", rigger_task_NODE_FAILURE);
  ASSERT_NE(skill_stopped, nullptr);
  ASSERT_NE(parallel_failed, nullptr);
  EXPECT_TRUE(skill_stopped->code.empty()) << skill_stopped->code;  // acknowledged, not timed out
  EXPECT_LE(skill_stopped->at, parallel_failed->at);
  EXPECT_EQ(parallel_failed->code, "FORCE_LIMIT");
  // The monitor is not shut down: it failed by itself.
  EXPECT_EQ(command_at("force", "root/1", rigger_skill_SKILL_SHUTDOWN), nullptr);
}

// Safety while paused: PAUSE reaches the monitor too, and monitor_host answers that it keeps
// monitoring (NOT_PAUSABLE); a force over the limit during the pause still fires it and fails the task,
// the skill (not pausable here either) being shut down first.
TEST_F(ControllerMonitorTest, AMonitorKeepsMonitoringWhileTheTaskIsPaused) {
  force_n_ = 5.0;
  start_stream();
  const json recipe = {{"recipe_version", 1},
                       {"task_id", "paused"},
                       {"root",
                        {{"type", "Parallel"},
                         {"success_threshold", 1},
                         {"failure_threshold", 1},
                         {"children",
                          {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
                           {{"type", "Monitor"}, {"monitor", "ForceMonitor"}, {"params", {{"max_force_n", 50.0}}}}}}}}};
  submit("paused", recipe);
  ASSERT_TRUE(wait_command("paused", "root/1", rigger_skill_SKILL_START));
  ASSERT_TRUE(cell_.wait_until([&] { return event_at("paused", "root/1", rigger_skill_SKILL_EVENT_ACCEPTED); }, 10s));
  command("paused", rigger_task_TASK_PAUSE, "hold");
  ASSERT_TRUE(wait_task("paused", rigger_task_TASK_PAUSED));
  ASSERT_TRUE(wait_command("paused", "root/1", rigger_skill_SKILL_PAUSE));
  ASSERT_TRUE(cell_.wait_until([&] { return event_at("paused", "root/1", rigger_skill_SKILL_EVENT_PAUSED); }, 10s));
  const EventSeen* answer = event_at("paused", "root/1", rigger_skill_SKILL_EVENT_PAUSED);
  EXPECT_EQ(answer->code, "NOT_PAUSABLE");
  EXPECT_NE(answer->message.find("keeps monitoring"), std::string::npos) << answer->message;

  force_n_ = 120.0;  // contact while paused
  ASSERT_TRUE(wait_finished("paused"));
  EXPECT_EQ(last("paused").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("paused").code, "FORCE_LIMIT") << last("paused").message;
  EXPECT_EQ(last("paused").failed_node, "root/1");
  EXPECT_NE(event_at("paused", "root/0", rigger_skill_SKILL_EVENT_STOPPED), nullptr);
  EXPECT_TRUE(has_line(journal("paused"), "root/1", "EVENT", "NOT_PAUSED"));
}

}  // namespace
}  // namespace rigger::testing::controller
