// The planner's responsiveness with a large tree: scripted executors announcing the real
// skill library, the world model, the CAD service and the console on a private DDS domain, and headless
// Debian chromium (playwright-core) opening generated trees of 10 (the reference) and 1,000 nodes in the
// planner and timing an edit's redraw and the tree's validation in the page, and the derivation of a
// screw list from the target's 4 holes through the console (test/bench/planner/tree.mjs prints them).
//
//   build/bench/bench_planner_tree [--trials 30] [--nodes 1000]
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "console_bench.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/testing/process.hpp"

int main(int argc, char** argv) {
  using namespace std::chrono_literals;
  using nlohmann::json;
  const int trials = rigger::bench::int_option(argc, argv, "--trials", 30);
  const int nodes = rigger::bench::int_option(argc, argv, "--nodes", 1000);
  const std::string repo = RIGGER_SOURCE_DIR;
  const std::string modules = rigger::bench::browser_modules();
  if (modules.empty()) return 2;

  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  auto config = [&](const std::string& name, const json& j) {
    const std::string path = dir + "/" + name + ".json";
    std::ofstream(path) << j.dump(2);
    return path;
  };
  const std::string library = repo + "/recipes/examples/skill_library.json";
  const std::string cell_file = repo + "/deploy/cell/simulated_cell.json";
  cell.start("world_model", "world_model",
             {"--id", "world_model", "--log-level", "warn", "--config",
              config("world_model", {{"cell_config", cell_file}}), "--db", dir + "/world_model.sqlite"});
  cell.start("cad", "cad",
             {"--id", "cad", "--log-level", "warn", "--config",
              config("cad", {{"cell_config", cell_file}, {"allowed_dirs", {repo + "/deploy/cell/models"}}})});
  cell.start("skills", "scripted_executor",
             {"--id", "skills", "--log-level", "warn", "--config",
              config("skills", {{"library_file", library}, {"skills", {"Localize"}}})});
  const auto console = rigger::bench::start_console(cell, {{"ada", rigger::console::Role::kProgrammer}});
  const auto& users = console.users;
  const std::uint16_t port = console.port;
  if (!cell.wait_ready({"world_model", "cad", "skills", "console"}, 60s)) {
    std::fprintf(stderr, "the services did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  bool done = false;
  rigger::testing::ChildProcess browser(
      "/usr/bin/node", {repo + "/test/bench/planner/tree.mjs"},
      {{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port)},
       {"TOKEN_PROGRAMMER", users[0].token},
       {"TRIALS", std::to_string(trials)},
       {"SIZES", "10," + std::to_string(nodes)},
       {"NODE_PATH", modules}},
      dir + "/browser.log", [&] { cell.loop().post([&] { done = true; }); });
  const bool ended = cell.wait_until([&] { return done; }, std::chrono::minutes(15));
  const auto exit = browser.wait(5s);
  std::printf("%s", browser.log().c_str());
  if (!ended || !exit || !exit->ok()) {
    std::fprintf(stderr, "the browser script failed (log above)\n");
    return 1;
  }

  rigger::performance::Report report("bench_planner_tree",
                                     "The planner in headless chromium: edits, redraws and validation of a " +
                                         std::to_string(nodes) + "-node tree (" + std::to_string(trials) +
                                         " trials) next to a 10-node tree, and the screw list next to GET /api/me");
  using rigger::bench::add_browser_row;
  const auto rows = rigger::bench::browser_rows(browser.log());
  const std::vector<std::string> levels = {"p50", "p90", "max"};
  bool ok = add_browser_row(report, rows, levels, "screw list from 4 picked holes",
                            "screw list from picked holes (POST /api/planner/screws)", 4, "GET /api/me",
                            "reference: GET /api/me", -1);
  for (const std::string label :
       {"POST /api/planner/validate alone (from node)", "POST /api/planner/validate alone (from the page)",
        "typed edit -> redrawn, laid out", "structural edit (Add) -> redrawn, laid out",
        "validation by the controller's validator -> marked"})
    ok = ok && add_browser_row(report, rows, levels, label, label, nodes, "10 nodes: " + label, label, 10);
  for (const std::string label : {"typed edit + validation (p50 sum)", "structural edit + validation (p50 sum)"})
    ok = ok && add_browser_row(report, rows, {""}, label, label, nodes, "10 nodes: " + label, label, 10);
  return ok ? rigger::performance::save_for_main(report) : 1;
}
