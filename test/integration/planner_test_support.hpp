#pragma once
// Shared by the planner's browser tests (planner_browser_test.cpp, planner_paper_task_test.cpp): the
// services the planner page talks to — the world model and the CAD service on the simulated cell's
// file and STEP models, scripted executors announcing the real skill library
// (recipes/examples/skill_library.json), the task controller and the console — on the test's private
// DDS domain, and a playwright-core script run against the console in headless Debian chromium.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "auth.hpp"
#include "cell_sim_test_support.hpp"
#include "scripted_library_support.hpp"

namespace rigger::testing {

/// True when the browser tests can run here: Debian's chromium, node and the console's npm packages.
inline bool browser_tools_present() {
  return std::filesystem::exists("/usr/bin/chromium") && std::filesystem::exists("/usr/bin/node") &&
         std::filesystem::exists(repo_file("services/console/web/node_modules/playwright-core"));
}

class PlannerCellTest : public MultiProcessTest {
 protected:
  std::string write_config(const std::string& name, const nlohmann::json& config) {
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << config.dump(2);
    return path;
  }

  /// Starts the planner's services and waits until each announced READY; sets port_ and token_ (the
  /// programmer "ada"). Skills succeed after 0.2 s, monitors run until stopped. `console_extra` is added
  /// to the console's configuration (e.g. its rehearsal_domain).
  ::testing::AssertionResult start_planner_services(const nlohmann::json& console_extra = nlohmann::json::object()) {
    const std::string dir = cell_.log_dir();
    const std::string cell_file = repo_file("deploy/cell/simulated_cell.json");
    cell_.start("world_model", "world_model",
                {"--id", "world_model", "--config", write_config("world_model", {{"cell_config", cell_file}}), "--db",
                 dir + "/world_model.sqlite"});
    cell_.start(
        "cad", "cad",
        {"--id", "cad", "--config",
         write_config("cad", {{"cell_config", cell_file}, {"allowed_dirs", {repo_file("deploy/cell/models")}}})});
    start_scripted_library_executors(
        cell_, {"Localize", "AttachRobotToLoad", "InsertVisuallyGuided", "Screw", "Release", "Place"});
    cell_.start("task_controller", "task_controller",
                {"--id", "task_controller", "--config",
                 write_config("task_controller", {{"journal_path", dir + "/journal.sqlite"}})});
    const auto users = console::make_users(dir + "/console-users.json", {{"ada", console::Role::kProgrammer}});
    token_ = users[0].token;
    port_ = free_tcp_port();
    nlohmann::json console_config = {{"port", port_},
                                     {"users_file", dir + "/console-users.json"},
                                     {"audit_log", dir + "/console-audit.log"}, {"runs_dir", dir + "/console-runs"},
                                     {"confirm_timeout_s", 30}};
    console_config.update(console_extra);
    cell_.start("console", "console", {"--id", "console", "--config", write_config("console", console_config)});
    if (!cell_.wait_ready({"world_model", "cad", "skills", "monitors", "task_controller", "console"},
                          std::chrono::seconds(60)))
      return ::testing::AssertionFailure() << "the planner's services did not all announce READY\n" << cell_.logs();
    return ::testing::AssertionSuccess();
  }

  /// A browser script started by start_browser_script(): its process, and whether it ended (set on the
  /// loops of the cells given at its start).
  struct BrowserScript {
    std::string script;
    std::unique_ptr<ChildProcess> process;
    std::shared_ptr<bool> ended = std::make_shared<bool>(false);
  };

  /// Starts `script` (a repository path) in node, niced, with the console's URL, the token, the log folder
  /// (ARTIFACTS) and `result_file` (RESULT) in its environment plus `env`; its end wakes the loops of
  /// `waiters` (the console's cell unless other cells' readers must follow the run).
  BrowserScript start_browser_script(const std::string& script, const std::string& result_file,
                                     std::map<std::string, std::string> env = {}, std::vector<Cell*> waiters = {}) {
    if (waiters.empty()) waiters.push_back(&cell_);
    env.insert({{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port_)},
                {"TOKEN_PROGRAMMER", token_},
                {"ARTIFACTS", cell_.log_dir()},
                {"RESULT", result_file},
                {"NODE_PATH", repo_file("services/console/web/node_modules")}});
    const std::string name = std::filesystem::path(script).stem().string();
    BrowserScript run{script, nullptr};
    // Shared: a script killed on timeout still posts its end to the loops after its waiter returned.
    run.process = std::make_unique<ChildProcess>(
        "/usr/bin/nice", std::vector<std::string>{"-n", "15", "/usr/bin/node", repo_file(script)}, env,
        cell_.log_dir() + "/browser-" + name + ".log", [waiters, ended = run.ended] {
          for (Cell* c : waiters) c->loop().post([ended] { *ended = true; });
        });
    return run;
  }

  /// Runs the loop of `waiter` (one of the script's waiters) until the script ended, at most `timeout`.
  /// Succeeds when it exited 0; the failure carries its log.
  ::testing::AssertionResult finish_browser_script(BrowserScript& run, Cell& waiter,
                                                   std::chrono::milliseconds timeout) {
    const bool ended = waiter.wait_until([&] { return *run.ended; }, timeout);
    const std::string log = run.process->log();
    if (!ended)
      return ::testing::AssertionFailure() << "the browser script " << run.script << " did not end in time\n" << log;
    const auto exit = run.process->wait(std::chrono::seconds(5));
    if (!exit || !exit->ok())
      return ::testing::AssertionFailure() << "the browser script " << run.script << " failed:\n" << log;
    std::printf("%s", log.c_str());
    return ::testing::AssertionSuccess();
  }

  /// start_browser_script() and finish_browser_script() within `timeout`, the loop of `waiter` (the
  /// console's cell unless another cell's readers must follow the run) running meanwhile.
  ::testing::AssertionResult run_browser_script(const std::string& script, const std::string& result_file,
                                                std::chrono::milliseconds timeout,
                                                std::map<std::string, std::string> env = {}, Cell* waiter = nullptr) {
    Cell& loop_cell = waiter != nullptr ? *waiter : cell_;
    BrowserScript run = start_browser_script(script, result_file, std::move(env), {&loop_cell});
    return finish_browser_script(run, loop_cell, timeout);
  }

  std::uint16_t port_ = 0;
  std::string token_;
};

/// Writes into `dir` (created) a rehearsal cell's start command for the console: a shell script running a
/// world model (on $RIGGER_CELL_FILE, the revision the console starts it on, when `on_revision`; else on
/// the simulated cell's file), scripted executors announcing the real skill library (skills succeed after
/// 0.2 s, monitors run) and a task controller, each writing its PID to `dir`/cell.pids. Returns the
/// script's path.
inline std::string write_scripted_rehearsal_cell(const std::string& dir, bool on_revision = false) {
  std::filesystem::create_directories(dir);
  const std::string library = repo_file("recipes/examples/skill_library.json");
  const auto config = [&](const std::string& name, const nlohmann::json& j) {
    std::ofstream(dir + "/" + name + ".json") << j.dump(2);
    return dir + "/" + name + ".json";
  };
  const std::string skills = config(
      "skills", {{"library_file", library},
                 {"skills", {"Localize", "AttachRobotToLoad", "InsertVisuallyGuided", "Screw", "Release", "Place", "MoveTo"}},
                 {"default", {{"mode", "succeed"}, {"delay_s", 0.2}}}});
  const std::string monitors = config("monitors", {{"library_file", library},
                                                   {"skills", {"TimerMonitor", "ForceMonitor", "YankMonitor"}},
                                                   {"default", {{"mode", "run"}}}});
  const std::string controller = config("task_controller", {{"journal_path", dir + "/journal.sqlite"}});
  const std::string world = config("world_model", {{"cell_config", repo_file("deploy/cell/simulated_cell.json")}});
  const std::string pids = dir + "/cell.pids";
  const std::string script = dir + "/rehearsal-cell.sh";
  std::ofstream out(script);
  out << "#!/bin/sh\n# The test's rehearsal cell: a controller and scripted executors on $RIGGER_DOMAIN.\n";
  const std::string world_args =
      world + " --db " + dir + "/world_model.sqlite" + (on_revision ? " --cell \"$RIGGER_CELL_FILE\"" : "");
  for (const auto& [id, binary, args] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"world_model", "world_model", world_args},
           {"skills", "scripted_executor", skills},
           {"monitors", "scripted_executor", monitors},
           {"task_controller", "task_controller", controller}})
    out << bin_dir() << "/" << binary << " --id " << id << " --config " << args << " & echo $! >> " << pids << "\n";
  out << "wait\n";
  return script;
}

/// A second cell on a DDS domain of its own (a leased id; logs in rehearsal/): the console's rehearsal
/// cell. Stopped after the test's own cell; its logs printed when the test failed.
template <typename Base>
class WithRehearsalCell : public Base {
 protected:
  void TearDown() override {
    Base::TearDown();
    const auto report = rehearsal_.stop_all();
    EXPECT_TRUE(report.ok) << report.problems;
    if (this->HasFailure())
      std::cerr << "===== logs of the rehearsal cell's processes (domain " << rehearsal_.domain_id() << ")\n"
                << rehearsal_.logs();
  }
  Cell rehearsal_{"rehearsal"};
};

}  // namespace rigger::testing
