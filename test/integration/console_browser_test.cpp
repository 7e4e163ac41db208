// The console in a real browser: the paper's scenario on every real process, the console on
// the same private DDS domain, and headless Debian chromium driven by playwright-core
// (console/e2e.mjs). No scripted operator runs: the four screw prompts are answered by clicks in the
// operator station. The browser script checks what the pages show (tree, the 3D view on the CAD
// service's geometry with each prompt's hole highlighted where its CAD position projects, the Tasks
// page's 3D cell, replay, plots, axe) and the refused requests (401, 403, 409); this test checks what
// the system did: the task SUCCEEDED, the tree the page showed is the tree the controller published,
// nothing started before the confirmed publish, the plotted force and tool speed are the physics' own
// over the insertion, and the replay's 3D cell has the load and the hook where the physics had them.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "auth.hpp"
#include "console/cell_trace.hpp"
#include "console/physics_trace.hpp"
#include "scenario_support.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing::scenario {
namespace {

bool browser_tools_present() {
  return std::filesystem::exists("/usr/bin/chromium") && std::filesystem::exists("/usr/bin/node") &&
         std::filesystem::exists(repo_file("services/console/web/node_modules/playwright-core"));
}

class ConsoleBrowserTest : public MultiProcessTest {};

// The console's plot rows: 20 per second (its default plot_rate_hz), each the mean wrench since the row before.
constexpr double kPlotRowS = 1.0 / 20.0;

// The plots page's |F| and tool speed over the insertion, against the physics at each row's time.
void expect_plots_are_the_physics(const ScenarioCell& scenario, const PhysicsTrace& physics, const nlohmann::json& plots) {
  const NodeView* insertion = scenario.node(ScenarioCell::kInsertion);
  ASSERT_TRUE(insertion != nullptr && insertion->finished_s > insertion->started_s) << "no finished insertion";
  const double from = insertion->started_s, to = insertion->finished_s;
  // The console's row averages the wrench since its previous row (one row period, longer when its loop
  // was late on a loaded machine).
  const auto force = compare_series(plots.at("f"), from, to, kPlotRowS,
                                    [&](double row_from, double t) { return physics.force_at(row_from, t); });
  const auto speed = compare_series(plots.at("robot_v"), from, to, kPlotRowS,
                                    [&](double, double t) { return physics.speed_at(t); });
  std::printf("  insertion %.2f s; physics %zu wrench, %zu robot samples\n  %s\n  %s\n", to - from,
              physics.force_samples(), physics.speed_samples(), force.describe("|F|", "N").c_str(),
              speed.describe("tool speed", "m/s").c_str());
  // Tolerances from two runs on a loaded 2-core machine (insertion 11.6 s, the restarted console's rows
  // over 10.2-10.7 s of it): 205-214 rows each; |F| peak page vs physics 3.25/3.33 N and 3.78/3.75 N
  // (within 3 %), row error median 0.005-0.007 N, max 0.48 N (the console averages by arrival, the
  // physics here by stamp: at a contact step a row's window differs by a sample or two); tool speed
  // peaks equal to 0.1 mm/s, row error median 0. Empty or zero series fail the row count or the peaks;
  // the same series moved by 1 s gave row error medians of 0.37 N and 5 mm/s, failing both.
  for (const auto* c : {&force, &speed}) EXPECT_GE(c->rows, 40) << "fewer than 2 s of rows inside the insertion";
  EXPECT_GT(force.physics_peak, 1.0) << "the physics pushed with no force: nothing to compare";
  EXPECT_GT(speed.physics_peak, 0.01) << "the tool did not move: nothing to compare";
  // The console averages the samples that arrived in a row's interval, the physics here those stamped in
  // it: a contact spike at a row's edge lands in one row or the next depending on its delivery lag, which
  // varies from sample to sample on a loaded machine (one row's peak was once 12 % under every constant
  // lag's). So the peaks compared are those of the mean over a few rows in a row, and the page's must
  // match the physics' for some lag of 0 to 20 ms, within 10 %.
  double lag_peak_lo = force.physics_window_peak, lag_peak_hi = force.physics_window_peak;
  for (const double lag_s : {0.002, 0.005, 0.01, 0.02}) {
    const double peak = compare_series(plots.at("f"), from, to, kPlotRowS, [&](double row_from, double t) {
                          return physics.force_at(row_from - lag_s, t - lag_s);
                        }).physics_window_peak;
    lag_peak_lo = std::min(lag_peak_lo, peak);
    lag_peak_hi = std::max(lag_peak_hi, peak);
  }
  std::printf("  |F| physics peak over %d rows for delivery lags of 0-20 ms: %.4f-%.4f N\n", kPeakWindowRows,
              lag_peak_lo, lag_peak_hi);
  EXPECT_GE(force.page_window_peak, 0.9 * lag_peak_lo) << "|F| peak";
  EXPECT_LE(force.page_window_peak, 1.1 * lag_peak_hi) << "|F| peak";
  EXPECT_NEAR(speed.page_peak, speed.physics_peak, 0.05 * speed.physics_peak) << "tool speed peak";
  EXPECT_LE(force.median_error, 0.1) << "|F| (N) row by row";
  EXPECT_LE(speed.median_error, 0.001) << "tool speed (m/s) row by row";
}

// The replay's 3D cell at each journaled step against the physics: the page shows the last position the
// console sent at or before the step, and it sends at most every 0.1 s; the crane's state passes the
// PLC and the gateway, the load's pose the camera, the tracker and the world model on its way.
constexpr double kCellWindowS = 0.5;
constexpr double kHookToleranceM = 0.005;
constexpr double kLoadMedianToleranceM = 0.01;

void expect_replay_cell_is_the_physics(const CellTrace& truth, const nlohmann::json& steps) {
  std::vector<double> load, hook;
  for (const auto& s : steps) {
    const double t = s.at("t").get<double>();
    const double l = truth.load_error(s.value("load", nlohmann::json()), t, kCellWindowS);
    const double h = truth.hook_error(s.value("hook", nlohmann::json()), t, kCellWindowS);
    if (!std::isnan(l)) load.push_back(l);
    if (!std::isnan(h)) hook.push_back(h);
  }
  const auto stats = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? std::pair(0.0, 0.0) : std::pair(v[v.size() / 2], v.back());
  };
  const auto [load_median, load_max] = stats(load);
  const auto [hook_median, hook_max] = stats(hook);
  std::printf("  replay 3D cell, %zu steps (%zu physics samples): load %zu compared, median %.1f mm, max %.1f mm; "
              "hook %zu compared, median %.1f mm, max %.1f mm\n",
              steps.size(), truth.samples(), load.size(), 1000 * load_median, 1000 * load_max, hook.size(),
              1000 * hook_median, 1000 * hook_max);
  EXPECT_GE(hook.size(), steps.size() / 2) << "the replay's hook has no physics to compare with";
  EXPECT_GE(load.size(), steps.size() / 2) << "the replay's load has no physics to compare with";
  EXPECT_LE(hook_max, kHookToleranceM) << "the replay's hook is not where the physics had it";
  EXPECT_LE(load_median, kLoadMedianToleranceM) << "the replay's load is not where the physics had it";
}

// Long enough for a dialog click in a loaded headless chromium (2.7 s seen), short enough to wait out.
constexpr double kConfirmTimeoutS = 5.0;

// The target's screw holes (target frame, m) as the CAD rules derive them from its STEP file: the truth
// the browser script projects with the page's camera, independent of what the page was told.
nlohmann::json cad_holes() {
  const cell::CellFile cell = cell::load_cell_file_with_cad(repo_file("deploy/cell/simulated_cell.json"));
  nlohmann::json holes = nlohmann::json::object();
  for (const auto& h : cell.require("target", "the operator station's 3D view").features.screw_holes) {
    const Eigen::Vector3d p = h.pose_entity_hole.translation();
    holes[h.id] = {p.x(), p.y(), p.z()};
  }
  return holes;
}

TEST_F(ConsoleBrowserTest, ScrewPromptsAnsweredInTheBrowserTaskSucceedsAndRefusalsMoveNothing) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  ScenarioCell scenario(cell_, {}, /*scripted_operator=*/false);
  ASSERT_TRUE(scenario.ready()) << "the cell did not come up";
  PhysicsTrace physics(cell_);
  CellTrace cell_truth(cell_);
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
                                                           {"audit_log", dir + "/console-audit.log"}, {"runs_dir", dir + "/console-runs"},
                                                           {"confirm_timeout_s", kConfirmTimeoutS}}
                                                .dump(2);
  }
  // The CAD service on the cell file and models the cell's other services read: the 3D view draws its
  // tessellation of the target.
  {
    std::ofstream(dir + "/cad.json") << nlohmann::json{{"cell_config", repo_file("deploy/cell/simulated_cell.json")},
                                                       {"allowed_dirs", {repo_file("deploy/cell/models")}}}
                                            .dump(2);
  }
  cell_.start("cad", "cad", {"--id", "cad", "--config", dir + "/cad.json"});
  cell_.start("console", "console", {"--config", dir + "/console.json"});
  ASSERT_TRUE(cell_.wait_ready({"cad", "console"}, 30s));

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
                        {"CAD_HOLES", cad_holes().dump()},
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
  double restart_s = 0;  // wall clock, s since the epoch
  if (!browser_done) {
    restart_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
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
  // Each prompt's hole was highlighted on screen where its CAD position projects (e2e.mjs measures).
  EXPECT_EQ(result.at("holes").size(), 4U) << result.at("holes").dump(2);
  for (const auto& [hole, h] : result.at("holes").items()) {
    std::printf("  hole %s: highlight %.2f px from its CAD position's projection (%d pixels)\n", hole.c_str(),
                h.at("distance_px").get<double>(), h.at("pixels").get<int>());
    EXPECT_LE(h.at("distance_px").get<double>(), 5.0) << hole << ": " << h.dump();
  }
  expect_plots_are_the_physics(scenario, physics, result.at("plots"));
  // The replay's plots are the run's, kept on disk across the console's restart: the same physics, and
  // rows from before the restart.
  expect_plots_are_the_physics(scenario, physics, result.at("replay_plots"));
  if (restarted) {
    ASSERT_FALSE(result.at("replay_plots").at("f").empty());
    EXPECT_LT(result.at("replay_plots").at("f").front().at(0).get<double>(), restart_s)
        << "the replay holds no plot row from before the console restarted";
  }
  expect_replay_cell_is_the_physics(cell_truth, result.at("replay_cell"));
  // Every action was journaled with who did it: the console's audit log names the users.
  std::ifstream audit(dir + "/console-audit.log");
  const std::string audit_text((std::istreambuf_iterator<char>(audit)), std::istreambuf_iterator<char>());
  EXPECT_NE(audit_text.find("\"user\":\"olu\""), std::string::npos) << audit_text;
  EXPECT_NE(audit_text.find("\"action\":\"publish\""), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", dir.c_str());
}

}  // namespace
}  // namespace rigger::testing::scenario
