// The scenario over three hosts: the fixture and the lab are in multi_host_support.hpp.
#include "multi_host_support.hpp"

namespace rigger::testing::scenario {
namespace {

TEST_F(MultiHostTest, CraneScenarioSucceedsOverThreeHosts) {
  ASSERT_TRUE(up_all());
  auto s = ScenarioCell::started_elsewhere(*cell_, kServices);
  ASSERT_TRUE(s->ready()) << "the devices host does not see every service of the three hosts READY";

  const auto services = on("controller", "services", riggerctl() + " services", 30s);
  EXPECT_TRUE(services.status.ok()) << services.output;
  for (const auto& id : kServices)
    EXPECT_NE(services.output.find("\n" + id + " "), std::string::npos) << id << " not seen from the controller host:\n"
                                                                     << services.output;

  const std::string id = task_id("run");
  s->watch(id);
  // The test's loop follows the task while riggerctl runs it: the simulator's truth is a keep-last-1 stream,
  // and a loop that waited for riggerctl to return read only the truth after the release.
  auto run = start_on("controller", "run", riggerctl() + " run recipes/crane_insert.json --task-id " + id);
  ASSERT_TRUE(cell_->wait_until([&] { return task_terminal(s->task_state()) || !run->running(); }, 300s))
      << s->task_summary();
  const auto ran = finish(*run, "riggerctl run", 30s);
  std::printf("--- riggerctl run on the controller host:\n%s\n", ran.output.c_str());
  EXPECT_TRUE(ran.status.ok()) << ran.output;
  ASSERT_TRUE(s->wait_task_end(30s)) << s->task_summary();
  print_report(*s, "crane insert over three hosts");
  EXPECT_EQ(s->task_state(), rigger_task_TASK_SUCCEEDED) << s->task_summary();
  // Where the load was once screwed on, before the release (the simulation has no screws: released, the
  // load hangs from the rope again), as ScenarioTest.CraneInsertSucceeds measures it.
  expect_screwed_on(*s);
}

}  // namespace
}  // namespace rigger::testing::scenario
