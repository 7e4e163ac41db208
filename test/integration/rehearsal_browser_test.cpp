// Rehearse, then publish: the console's cell (its own DDS domain) has a task controller with
// scripted executors and no devices; the rehearsal cell is the full simulated cell with real physics
// (cell_sim, crane gateway, admittance, tracker, world model, the real skill executors, the scripted
// operator, a controller) on a second domain of its own, which the console joins through
// rehearsal_domain. Headless Debian chromium (rehearsal/e2e.mjs, playwright-core) opens
// recipes/examples/attach_load.json on the planner, clicks Rehearse, and follows the run in the
// rehearsal view to its end. (The paper's whole task is rehearsed by PlannerRehearsalTest, built by
// clicks; what this test checks does not depend on the recipe, so it rehearses a short one.) This test checks on DDS that the task SUCCEEDED on the rehearsal domain with the node
// states the page showed, and that nothing at all was published on the cell's domain; the browser
// script also checks the refusals (no rehearsal domain configured, a viewer).
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "auth.hpp"
#include "planner_test_support.hpp"
#include "scenario_support.hpp"
#include "scripted_library_support.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing::scenario {
namespace {

using RehearsalBrowserTest = WithRehearsalCell<PlannerCellTest>;

TEST_F(RehearsalBrowserTest, AnAttachRehearsedOnTheSimulatedCellSucceedsLiveInThePageAndNothingReachesTheCell) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  ASSERT_NE(cell_.domain_id(), rehearsal_.domain_id());
  const std::string dir = cell_.log_dir();

  // The cell's domain: what reaches it is recorded from the start (recipes are volatile: a reader made
  // later would miss them; task statuses are transient-local anyway).
  dds::Reader<rigger_task_Recipe> cell_recipes(cell_.participant(), protocol::task::kRecipe);
  dds::Reader<rigger_task_TaskStatus> cell_tasks(cell_.participant(), protocol::task::kStatus);

  // The rehearsal cell, as the scenario tests run it, with the scripted operator answering the screws.
  ScenarioCell sim(rehearsal_);
  ASSERT_TRUE(sim.ready()) << "the rehearsal cell did not come up\n" << rehearsal_.logs();
  std::ifstream recipe_file(repo_file("recipes/examples/attach_load.json"));
  const std::string task_id = nlohmann::json::parse(recipe_file).at("task_id");
  sim.watch(task_id);

  // The console's cell: a controller and scripted executors announcing the real skill library, no devices.
  start_scripted_library_executors(
      cell_, {"Localize", "AttachRobotToLoad", "InsertVisuallyGuided", "Screw", "Release", "Place", "MoveTo"});
  cell_.start("task_controller", "task_controller",
              {"--id", "task_controller", "--config",
               write_config("task_controller", {{"journal_path", dir + "/journal.sqlite"}})});
  const auto users = console::make_users(dir + "/console-users.json",
                                         {{"ada", console::Role::kProgrammer}, {"vic", console::Role::kViewer}});
  const std::uint16_t port = free_tcp_port();
  const std::uint16_t plain_port = free_tcp_port();
  const nlohmann::json console_config = {{"users_file", dir + "/console-users.json"},
                                         {"audit_log", dir + "/console-audit.log"}, {"runs_dir", dir + "/console-runs"},
                                         {"confirm_timeout_s", 30}};
  nlohmann::json with_rehearsal = console_config;
  with_rehearsal["port"] = port;
  with_rehearsal["rehearsal_domain"] = rehearsal_.domain_id();
  nlohmann::json plain = console_config;
  plain["port"] = plain_port;
  plain["audit_log"] = dir + "/console-plain-audit.log";
  plain["runs_dir"] = dir + "/console-plain-runs";
  cell_.start("console", "console", {"--id", "console", "--config", write_config("console", with_rehearsal)});
  cell_.start("console-plain", "console", {"--id", "console-plain", "--config", write_config("console-plain", plain)});
  ASSERT_TRUE(cell_.wait_ready({"skills", "monitors", "task_controller", "console", "console-plain"}, 60s))
      << cell_.logs();

  const std::string result_file = dir + "/rehearsal-result.json";
  bool browser_done = false;
  const auto t0 = Clock::now();
  // Niced: the rehearsal cell's real-time loops must not starve behind chromium's software rendering.
  ChildProcess browser("/usr/bin/nice", {"-n", "15", "/usr/bin/node", repo_file("test/integration/rehearsal/e2e.mjs")},
                       {{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port)},
                        {"PLAIN_URL", "http://127.0.0.1:" + std::to_string(plain_port)},
                        {"TOKEN_PROGRAMMER", users[0].token},
                        {"TOKEN_VIEWER", users[1].token},
                        {"REHEARSAL_DOMAIN", std::to_string(rehearsal_.domain_id())},
                        {"RECIPE", repo_file("recipes/examples/attach_load.json")},
                        {"ARTIFACTS", dir},
                        {"RESULT", result_file},
                        {"NODE_PATH", repo_file("services/console/web/node_modules")}},
                       dir + "/browser.log", [&] { rehearsal_.loop().post([&] { browser_done = true; }); });
  // The rehearsal cell's loop runs meanwhile: the scenario's readers follow the task on its domain.
  const bool ended = rehearsal_.wait_until([&] { return browser_done; }, std::chrono::minutes(7));
  const std::string browser_log = browser.log();
  ASSERT_TRUE(ended) << "the browser script did not end within 7 min\n" << browser_log << "\n" << sim.task_summary();
  const auto exit = browser.wait(5s);
  ASSERT_TRUE(exit && exit->ok()) << "the browser script failed:\n" << browser_log << "\n" << sim.task_summary();
  std::printf("browser script (cell up to the rehearsal's end in the page): %.1f s\n",
              std::chrono::duration<double>(Clock::now() - t0).count());

  // On the rehearsal domain: the task SUCCEEDED, and the page showed every node's final state as the
  // rehearsal controller published it.
  ASSERT_TRUE(sim.wait_task_end(30s)) << sim.task_summary();
  EXPECT_EQ(sim.task_state(), rigger_task_TASK_SUCCEEDED) << sim.task_summary();
  std::printf("rehearsal of %s on domain %u:\n%s", task_id.c_str(), rehearsal_.domain_id(), sim.durations().c_str());
  std::ifstream in(result_file);
  const nlohmann::json result = nlohmann::json::parse(in);
  EXPECT_EQ(result.at("task_state"), "SUCCEEDED");
  EXPECT_EQ(result.at("title"), "Rehearsal — simulated cell, domain " + std::to_string(rehearsal_.domain_id()));
  const nlohmann::json& shown = result.at("shown");
  ASSERT_FALSE(sim.nodes().empty());
  EXPECT_EQ(shown.size(), sim.nodes().size()) << shown.dump(2);
  for (const auto& [node_id, node] : sim.nodes()) {
    ASSERT_TRUE(shown.contains(node_id)) << node_id << " is not shown\n" << shown.dump(2);
    EXPECT_EQ(shown.at(node_id), ScenarioCell::state_name(node.state)) << node_id << " (" << node.name << ")";
  }
  EXPECT_EQ(shown.at("root"), "SUCCESS");

  // On the cell's domain: no recipe was written and no task exists.
  int recipes_on_cell = 0, tasks_on_cell = 0;
  cell_recipes.take([&](const rigger_task_Recipe&, const dds_sample_info_t&) { ++recipes_on_cell; });
  cell_tasks.take([&](const rigger_task_TaskStatus&, const dds_sample_info_t&) { ++tasks_on_cell; });
  EXPECT_EQ(recipes_on_cell, 0) << "a recipe reached the cell's domain";
  EXPECT_EQ(tasks_on_cell, 0) << "a task exists on the cell's domain";
  // The cell's controller heard the console's recipe topic all along (the check above could fail).
  EXPECT_GE(cell_recipes.matched_writers(), 2u);

  // Journaled with who, one step (no confirmation).
  std::ifstream audit(dir + "/console-audit.log");
  const std::string audit_text((std::istreambuf_iterator<char>(audit)), std::istreambuf_iterator<char>());
  EXPECT_NE(audit_text.find("\"action\":\"rehearse\""), std::string::npos) << audit_text;
  EXPECT_NE(audit_text.find("sent to rehearsal domain " + std::to_string(rehearsal_.domain_id())), std::string::npos)
      << audit_text;
  EXPECT_EQ(audit_text.find("\"action\":\"publish\""), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", dir.c_str());
}

// A rehearsal on the cell's own domain would run on the real cell: the console refuses to start (exit 2,
// naming the key), before it reads its users.
TEST_F(RehearsalBrowserTest, TheCellsOwnDomainAsRehearsalDomainIsRefusedAtStart) {
  expect_clean_exit_ = false;  // the console exits 2, as it should
  expect_refused_configuration(cell_, "console",
                               nlohmann::json{{"port", 0}, {"rehearsal_domain", cell_.domain_id()}}.dump(),
                               "/rehearsal_domain");
}

}  // namespace
}  // namespace rigger::testing::scenario
