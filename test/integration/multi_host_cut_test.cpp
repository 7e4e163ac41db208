// A host's link cut during the insertion, on the lab of multi_host_support.hpp. It asserts the safety target
// scaled to the lease it runs with (below). Three hosts' worth of processes on two cores: under load it
// has failed on scheduling (a 104 ms gap in the 500 Hz wrench stream against the yank monitor's 100 ms),
// see docs/deploy.md.
#include "multi_host_support.hpp"
#include "rigger/dds/qos.hpp"

namespace rigger::testing::scenario {
namespace {


// The scenario over three hosts, with the skills host's cable pulled while the load is being inserted.
// The controller host sees every service of the three hosts; the robot attaches to the load across them.
// The cut: the controller loses the executors and stops the leaf's devices; robot and crane come to rest;
// the task fails with EXECUTOR_LOST. Cable back in: the services are seen again without a restart, nothing
// sent before the cut moves anything, and after the operator resets the stops a second run does the rest
// of the task over the three hosts (localize, insert, screw, release): it succeeds, and the load is where
// the one-host scenario puts it, within 5 mm and 1 degree of its insertion pose when the release starts.
TEST_F(MultiHostTest, SkillsHostCutDuringInsertionStopsTheCellAndItRecovers) {
  ASSERT_TRUE(up_all());
  auto s = ScenarioCell::started_elsewhere(*cell_, kServices);
  ASSERT_TRUE(s->ready()) << "the devices host does not see every service of the three hosts READY";
  const auto services = on("controller", "services", riggerctl() + " services", 30s);
  EXPECT_TRUE(services.status.ok()) << services.output;
  for (const auto& id : kServices)
    EXPECT_NE(services.output.find("\n" + id + " "), std::string::npos) << id << " not seen from the controller host:\n"
                                                                     << services.output;

  const std::string first = task_id("cut");
  s->watch(first);
  auto run = start_on("controller", "run-cut", riggerctl() + " run recipes/crane_insert.json --task-id " + first);
  ASSERT_TRUE(s->wait_node("insert visually guided", rigger_task_NODE_RUNNING, 180s)) << s->task_summary();
  const auto start = s->truth("load");
  ASSERT_TRUE(start.has_value());
  ASSERT_TRUE(cell_->wait_until(
      [&] {
        const auto now = s->truth("load");
        return task_terminal(s->task_state()) || (now && (now->translation() - start->translation()).norm() > 0.05);
      },
      120s));
  ASSERT_FALSE(task_terminal(s->task_state())) << s->task_summary();

  // The cut runs while this process keeps reading the cell (a blocking wait would stamp the samples queued
  // meanwhile with the time they are read): times count from the start of the command, which pulls the cable
  // as its last step.
  const auto cut_at = Clock::now();
  s->mark_stop(cut_at);
  auto cut = this->start("deploy/lab-hosts cut skills", "lab-cut");  // `start` here is the load's pose
  ASSERT_TRUE(cell_->wait_until([&] { return !cut->running(); }, 60s));
  const double cut_command_s = std::chrono::duration<double>(Clock::now() - cut_at).count();
  ASSERT_TRUE(finish(*cut, "deploy/lab-hosts cut skills", 5s).status.ok());
  const auto after = s->motion_after_stop(200);
  const double rest_s = std::chrono::duration<double>(after.rest_at - cut_at).count();
  std::printf("  skills host cut: robot and crane at rest within %.2f s; then over 2 s: tool %.2f mm, crane %.1f mm/s\n",
              rest_s, after.max_tool_m * 1000.0, after.max_crane_mps * 1000.0);
  const auto below = s->rest_after_mark_s();
  std::printf(
      "  below 1 mm/s (tool and crane) %.0f ms after the cut command started (it took %.0f ms; tool alone "
      "%.0f ms, crane alone %.0f ms); last above it %.0f ms after; where the time went:\n%s",
      below.value_or(-1.0) * 1000.0, cut_command_s * 1000.0, s->tool_rest_after_mark_s().value_or(-1.0) * 1000.0,
      s->crane_rest_after_mark_s().value_or(-1.0) * 1000.0, s->settled_after_mark_s().value_or(-1.0) * 1000.0,
      s->stop_timeline().c_str());
  RecordProperty("rest_after_cut_ms", std::to_string(static_cast<int>(below.value_or(-1.0) * 1000.0)));
  ASSERT_TRUE(below.has_value()) << "the tool or the crane never came below 1 mm/s after the cut";
  // The safety target: at rest for good within the liveliness lease + 350 ms of the cut, i.e. 500 ms with
  // the shipped 150 ms lease. The three hosts' processes do not keep the shipped lease on the 2-core test
  // machine (a false liveliness lapse before the cut), so test/run runs this test with the suite's 300 ms
  // lease and the bound follows the lease (docs/testing.md).
  const double lease_s = std::chrono::duration<double>(dds::liveliness_lease()).count();
  const auto settled = s->settled_after_mark_s();
  ASSERT_TRUE(settled.has_value());
  EXPECT_LT(*settled, lease_s + 0.35) << "robot or crane last above 1 mm/s " << *settled * 1000.0
                                      << " ms after the cut command started (lease " << lease_s * 1000.0
                                      << " ms); where the time went:\n"
                                      << s->stop_timeline();
  EXPECT_TRUE(after.at_rest) << "robot or crane still moving 5 s after the cut";
  EXPECT_LT(after.max_tool_m, 0.002);
  EXPECT_LT(after.max_crane_mps, 0.005);
  EXPECT_TRUE(s->gripper_holding()) << "the load must stay held";
  ASSERT_TRUE(s->wait_task_end(30s)) << s->task_summary();
  EXPECT_EQ(s->task_state(), rigger_task_TASK_FAILED);
  EXPECT_EQ(s->task_code(), "EXECUTOR_LOST") << s->task_summary();
  const auto ended = finish(*run, "riggerctl run (cut)", 30s);
  EXPECT_FALSE(ended.status.ok()) << ended.output;
  std::printf("--- riggerctl run during the cut:\n%s\n", ended.output.c_str());

  // Cable back in: every service READY again on DDS, with no restart; whatever the skills host had queued
  // before the cut must not move the stopped devices.
  ASSERT_TRUE(lab("restore", {"skills"}).status.ok());
  const auto restored_at = Clock::now();
  ASSERT_TRUE(cell_->wait_ready(kServices, 30s)) << "the cell did not come back after the link returned";
  std::printf("  link restored: every service READY again after %.2f s\n",
              std::chrono::duration<double>(Clock::now() - restored_at).count());
  const auto still = s->motion_after_stop(200);
  EXPECT_TRUE(still.at_rest);
  EXPECT_LT(still.max_tool_m, 0.002) << "a command from before the cut moved the robot";
  EXPECT_LT(still.max_crane_mps, 0.005) << "a command from before the cut moved the crane";

  const auto ps = on("skills", "ps", compose() + " ps", 30s);
  EXPECT_EQ(ps.output.find("LOST"), std::string::npos) << ps.output;

  // The operator looks, resets the stops the controller wrote, and runs the rest of the task: the robot
  // still holds the load over the target, so a recipe of the remaining steps (localize both again, the
  // insertion with its fallback, the screws, the release) made from the shipped one, with the attachment
  // as an assumption. (Resuming from the journal after a cut is not done yet.)
  const auto reset = on("controller", "reset", riggerctl() + " estop --reset", 30s);
  ASSERT_TRUE(reset.status.ok()) << reset.output;
  std::ifstream shipped(RIGGER_SOURCE_DIR "/recipes/crane_insert.json");
  const nlohmann::json full = nlohmann::json::parse(shipped);
  const nlohmann::json& steps = full.at("root").at("children");
  nlohmann::json rest = full;
  rest["description"] = "the rest of the crane insertion, after a stop with the load held";
  rest["assumptions"].push_back("attached(robot,load)");
  rest["root"]["children"] = nlohmann::json::array({steps.at(0), steps.at(1).at("child").at("children").at(0)});
  for (std::size_t i = 2; i < steps.size(); ++i) rest["root"]["children"].push_back(steps.at(i));
  ASSERT_EQ(rest["root"]["children"][1].value("skill", ""), "Localize");
  const std::string second = task_id("again");
  rest["task_id"] = second;
  const std::string rest_file = cell_->log_dir() + "/rest_of_the_task.json";
  std::ofstream(rest_file) << rest.dump(2);
  s->watch(second);
  // The test's loop follows the task while riggerctl runs it: the simulator's truth is a keep-last-1 stream,
  // and a loop that waited for riggerctl to return would read only the truth after the release.
  auto run_again = start_on("controller", "run-again", riggerctl() + " run " + rest_file);
  ASSERT_TRUE(cell_->wait_until([&] { return task_terminal(s->task_state()) || !run_again->running(); }, 300s))
      << s->task_summary();
  const auto again = finish(*run_again, "riggerctl run (again)", 30s);
  std::printf("--- the second run:\n%s\n", again.output.c_str());
  EXPECT_TRUE(again.status.ok()) << again.output;
  ASSERT_TRUE(s->wait_task_end(30s)) << s->task_summary();
  print_report(*s, "the rest of the crane insert over three hosts");
  EXPECT_EQ(s->task_state(), rigger_task_TASK_SUCCEEDED) << s->task_summary();
  // Where the load was once screwed on, before the release (the simulation has no screws), as
  // ScenarioTest.CraneInsertSucceeds measures it.
  expect_screwed_on(*s);
}

}  // namespace
}  // namespace rigger::testing::scenario
