// The console in a real browser: the paper's scenario on every real process, the console on
// the same private DDS domain, and headless Debian chromium driven by playwright-core
// (console/e2e.mjs). No scripted operator runs: the four screw prompts are answered by clicks in the
// operator station. The browser script checks what the pages show (tree, 3D highlight, replay, axe)
// and the refused requests (401, 403, 409); this test checks what the system did: the task
// SUCCEEDED, the tree the page showed is the tree the controller published, and nothing started
// before the confirmed publish.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "auth.hpp"
#include "scenario_support.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing::scenario {
namespace {

bool browser_tools_present() {
  return std::filesystem::exists("/usr/bin/chromium") && std::filesystem::exists("/usr/bin/node") &&
         std::filesystem::exists(repo_file("services/console/web/node_modules/playwright-core"));
}

class ConsoleBrowserTest : public MultiProcessTest {};

// Long enough for a dialog click in a loaded headless chromium (2.7 s seen), short enough to wait out.
constexpr double kConfirmTimeoutS = 5.0;

TEST_F(ConsoleBrowserTest, ScrewPromptsAnsweredInTheBrowserTaskSucceedsAndRefusalsMoveNothing) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  ScenarioCell scenario(cell_, {}, /*scripted_operator=*/false);
  ASSERT_TRUE(scenario.ready()) << "the cell did not come up";
  std::ifstream recipe_file(repo_file("recipes/crane_insert.json"));
  const std::string task_id = nlohmann::json::parse(recipe_file).at("task_id");
  scenario.watch(task_id);

  const std::string dir = cell_.log_dir();
  const auto users = console::make_users(dir + "/console-users.json", {{"ada", console::Role::kProgrammer},
                                                                       {"olu", console::Role::kOperator},
                                                                       {"vic", console::Role::kViewer}});
  const std::uint16_t port = free_tcp_port();
  {
    std::ofstream(dir + "/console.json") << nlohmann::json{{"port", port},
                                                           {"users_file", dir + "/console-users.json"},
                                                           {"audit_log", dir + "/console-audit.log"},
                                                           {"confirm_timeout_s", kConfirmTimeoutS}}
                                                .dump(2);
  }
  cell_.start("console", "console", {"--config", dir + "/console.json"});
  ASSERT_TRUE(cell_.wait_ready({"console"}, 20s));

  const std::string result_file = dir + "/browser-result.json";
  bool browser_done = false;
  // Niced: the cell's real-time loops (physics, PLC link, 500 Hz wrench) must not starve behind
  // chromium's software WebGL on a small machine.
  ChildProcess browser("/usr/bin/nice", {"-n", "15", "/usr/bin/node", repo_file("test/integration/console/e2e.mjs")},
                       {{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port)},
                        {"TOKEN_PROGRAMMER", users[0].token},
                        {"TOKEN_OPERATOR", users[1].token},
                        {"TOKEN_VIEWER", users[2].token},
                        {"RECIPE", repo_file("recipes/crane_insert.json")},
                        {"ARTIFACTS", dir},
                        {"RESULT", result_file},
                        {"CONFIRM_TIMEOUT_S", std::to_string(kConfirmTimeoutS)},
                        {"NODE_PATH", repo_file("services/console/web/node_modules")}},
                       dir + "/browser.log", [&] { cell_.loop().post([&] { browser_done = true; }); });
  // Mid-task (the insertion running, the browser watching), the console is restarted on the same port:
  // the pages' event streams reconnect to a console of another run, get a reset and reload the state.
  const auto node_running = [&](const std::string& name) {
    const NodeView* n = scenario.node(name);
    return n != nullptr && n->state == rigger_task_NODE_RUNNING;
  };
  ASSERT_TRUE(cell_.wait_until([&] { return browser_done || node_running("insert visually guided"); }, std::chrono::minutes(4)))
      << "the insertion did not start\n" << browser.log();
  bool restarted = false;
  if (!browser_done) {
    const auto stopped = cell_.stop("console", SIGINT, 10s);
    ASSERT_TRUE(stopped && stopped->ok()) << "the console did not stop cleanly";
    cell_.start("console-restarted", "console", {"--id", "console-restarted", "--config", dir + "/console.json"});
    ASSERT_TRUE(cell_.wait_ready({"console-restarted"}, 20s));
    restarted = true;
  }
  const bool ended = cell_.wait_until([&] { return browser_done; }, std::chrono::minutes(7));
  const std::string browser_log = browser.log();
  ASSERT_TRUE(ended) << "the browser script did not end within 7 min\n" << browser_log;
  const auto status = browser.wait(5s);
  ASSERT_TRUE(status && status->ok()) << "the browser script failed:\n" << browser_log;

  // What the system did.
  ASSERT_TRUE(scenario.wait_task_end(30s));
  EXPECT_EQ(scenario.task_state(), rigger_task_TASK_SUCCEEDED) << scenario.task_summary();
  std::ifstream in(result_file);
  const nlohmann::json result = nlohmann::json::parse(in);
  // Nothing reached the controller before the confirmed publish: the refused publishes left no task.
  EXPECT_TRUE(result.at("tasks_after_refusals").empty()) << result.dump(2);
  // Every node the controller published is on the page, in its final state.
  const auto& page_tree = result.at("page_tree");
  ASSERT_FALSE(scenario.nodes().empty());
  for (const auto& [id, n] : scenario.nodes()) {
    ASSERT_TRUE(page_tree.contains(id)) << "node " << id << " (" << n.name << ") is not on the Tasks page";
    EXPECT_EQ(page_tree.at(id).get<std::string>(), ScenarioCell::state_name(n.state)) << "node " << id;
  }
  EXPECT_EQ(result.at("screws_answered").get<int>(), 4);
  if (restarted) {
    EXPECT_GE(result.at("resets").at("programmer").get<int>(), 1) << "the Tasks page did not see the restart";
    EXPECT_GE(result.at("resets").at("operator").get<int>(), 1) << "the operator station did not see the restart";
  }
  EXPECT_EQ(result.at("replay_tree"), page_tree) << "the replay's last step differs from the live tree";
  EXPECT_TRUE(std::filesystem::exists(dir + "/operator-station-hole-1.png"));
  // Every action was journaled with who did it: the console's audit log names the users.
  std::ifstream audit(dir + "/console-audit.log");
  const std::string audit_text((std::istreambuf_iterator<char>(audit)), std::istreambuf_iterator<char>());
  EXPECT_NE(audit_text.find("\"user\":\"olu\""), std::string::npos) << audit_text;
  EXPECT_NE(audit_text.find("\"action\":\"publish\""), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", dir.c_str());
}

}  // namespace
}  // namespace rigger::testing::scenario
