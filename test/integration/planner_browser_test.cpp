// The console's planner in a real browser (issue 16, first slice): the real CAD service (the cell's STEP
// models), the real world model, the task controller, scripted executors announcing the real skill
// library (recipes/examples/skill_library.json), and the console, all on a private DDS domain; headless
// Debian chromium driven by playwright-core (planner/e2e.mjs) builds a tree by clicks, picks the
// target's holes in the 3D view, binds the Screw skill's holes, sees a bad Parallel threshold flagged on
// its node and field, fixes it, exports and publishes. This test checks what the system did: the
// exported recipe validates and carries the CAD-derived screw positions, and the published task ran.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "auth.hpp"
#include "cell_sim_test_support.hpp"
#include "scripted_library_support.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/task_names.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

bool browser_tools_present() {
  return std::filesystem::exists("/usr/bin/chromium") && std::filesystem::exists("/usr/bin/node") &&
         std::filesystem::exists(repo_file("services/console/web/node_modules/playwright-core"));
}

class PlannerBrowserTest : public MultiProcessTest {
 protected:
  std::string write_config(const std::string& name, const json& config) {
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << config.dump(2);
    return path;
  }
};

TEST_F(PlannerBrowserTest, TreeBuiltByClicksScrewsFromPickedHolesValidatedExportedAndPublished) {
  if (!browser_tools_present())
    GTEST_SKIP() << "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)";
  const std::string dir = cell_.log_dir();
  const std::string cell_file = repo_file("deploy/cell/simulated_cell.json");

  std::map<std::string, int> task_states;
  dds::Reader<rigger_task_TaskStatus> status(cell_.participant(), protocol::task::kStatus);
  cell_.loop().on_data(status, [&] {
    status.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      task_states[dds::to_string(s.task_id)] = s.state;
    });
  });

  cell_.start("world_model", "world_model",
              {"--id", "world_model", "--config", write_config("world_model", {{"cell_config", cell_file}}), "--db",
               dir + "/world_model.sqlite"});
  cell_.start("cad", "cad",
              {"--id", "cad", "--config",
               write_config("cad", {{"cell_config", cell_file}, {"allowed_dirs", {repo_file("deploy/cell/models")}}})});
  start_scripted_library_executors(
      cell_, {"Localize", "AttachRobotToLoad", "InsertVisuallyGuided", "Screw", "Release", "Place"});
  cell_.start("task_controller", "task_controller",
              {"--id", "task_controller", "--config",
               write_config("task_controller", {{"journal_path", dir + "/journal.sqlite"}})});
  const auto users = console::make_users(dir + "/console-users.json", {{"ada", console::Role::kProgrammer}});
  const std::uint16_t port = free_tcp_port();
  cell_.start("console", "console",
              {"--id", "console", "--config",
               write_config("console", {{"port", port},
                                        {"users_file", dir + "/console-users.json"},
                                        {"audit_log", dir + "/console-audit.log"},
                                        {"confirm_timeout_s", 30}})});
  ASSERT_TRUE(cell_.wait_ready({"world_model", "cad", "skills", "monitors", "task_controller", "console"}, 60s))
      << cell_.logs();

  const std::string result_file = dir + "/planner-result.json";
  bool browser_done = false;
  ChildProcess browser("/usr/bin/nice", {"-n", "15", "/usr/bin/node", repo_file("test/integration/planner/e2e.mjs")},
                       {{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port)},
                        {"TOKEN_PROGRAMMER", users[0].token},
                        {"ARTIFACTS", dir},
                        {"RESULT", result_file},
                        {"NODE_PATH", repo_file("services/console/web/node_modules")}},
                       dir + "/browser.log", [&] { cell_.loop().post([&] { browser_done = true; }); });
  const bool ended = cell_.wait_until([&] { return browser_done; }, std::chrono::minutes(6));
  const std::string browser_log = browser.log();
  ASSERT_TRUE(ended) << "the browser script did not end within 6 min\n" << browser_log;
  const auto exit = browser.wait(5s);
  ASSERT_TRUE(exit && exit->ok()) << "the browser script failed:\n" << browser_log;

  std::ifstream in(result_file);
  const json result = json::parse(in);
  // The exported recipe is canonical JSON and its Screw node's holes are the world model's features,
  // with the binding (model sha256, references with signatures, CAD-derived poses) kept.
  const std::string exported = result.at("exported");
  const json recipe = json::parse(exported);
  EXPECT_EQ(exported, recipe.dump(2) + "\n") << "the export is not in canonical form";
  const json& screw = recipe.at("root").at("children").at(1);
  ASSERT_EQ(screw.at("skill"), "Screw") << recipe.dump(2);
  const json& binding = screw.at("bindings").at("holes");
  const json& cad_holes = result.at("cad_holes");
  ASSERT_EQ(binding.at("screws").size(), 4u);
  ASSERT_EQ(screw.at("params").at("holes").size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const json& s = binding.at("screws").at(i);
    EXPECT_EQ(s.at("ref").at("model_sha256"), binding.at("model_sha256"));
    EXPECT_TRUE(s.at("ref").at("signature").contains("radius_m"));
    EXPECT_EQ(screw.at("params").at("holes").at(i), s.at("feature"));
    // The picks were in the order h0, h1, h2, h3 of the CAD model: the positions are the CAD service's.
    EXPECT_EQ(s.at("hole"), cad_holes.at(i).at("index"));
    EXPECT_EQ(s.at("pose").at("position_m"), cad_holes.at(i).at("entry_m"));
  }
  // The page showed the Parallel's threshold error on that node and field, from the controller's validator.
  EXPECT_EQ(result.at("threshold_error").at("node"), "/root/children/0");
  EXPECT_NE(result.at("threshold_error").at("field").get<std::string>().find("success_threshold"), std::string::npos);

  // Published with the two-step confirmation: the controller ran the planned task to the end.
  const std::string task_id = recipe.at("task_id");
  ASSERT_TRUE(cell_.wait_until([&] {
    auto it = task_states.find(task_id);
    return it != task_states.end() && (it->second == rigger_task_TASK_SUCCEEDED || it->second == rigger_task_TASK_FAILED ||
                                       it->second == rigger_task_TASK_REJECTED);
  }, 60s)) << "the published task did not end\n" << cell_.logs();
  EXPECT_EQ(task_states[task_id], rigger_task_TASK_SUCCEEDED) << protocol::task::task_state_name(task_states[task_id]);
  std::ifstream audit(dir + "/console-audit.log");
  const std::string audit_text((std::istreambuf_iterator<char>(audit)), std::istreambuf_iterator<char>());
  EXPECT_NE(audit_text.find("\"action\":\"publish\""), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", dir.c_str());
}

}  // namespace
}  // namespace rigger::testing
