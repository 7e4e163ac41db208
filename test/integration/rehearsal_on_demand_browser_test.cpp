// Rehearse with no rehearsal cell running: the console starts it. The console's cell is the planner's
// (world model, CAD, scripted executors, a controller); its configuration has a rehearsal domain and a
// start command — a shell script that runs a world model on the cell's file, a task controller and
// scripted executors announcing the real skill library on $RIGGER_DOMAIN, writing their PIDs — with a
// 3 s idle stop. Headless chromium (rehearsal/on_demand.mjs) first moves the target by a cell revision
// on the console's domain, then opens recipes/crane_insert.json on the planner and clicks Rehearse: the
// page says it is starting the rehearsal cell, then shows the run to SUCCEEDED; the target moves again
// and the recipe is rehearsed once more (over HTTP, a new task id) while the cell is up; back on the plan,
// nobody watches, and the console stops the cell. This test checks on the rehearsal domain that its
// world model reported each of the real cell's revisions (by sha256, applied by the user) before the
// controller gave the task rehearsed on it a status, that every process of that cell is gone (by PID)
// and that the audit log has the start (by the user) and the stop.
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "planner_test_support.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/require.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using RehearsalOnDemandTest = WithRehearsalCell<PlannerCellTest>;

std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST_F(RehearsalOnDemandTest, RehearseStartsTheRehearsalCellAndItStopsWhenIdle) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  const std::string dir = rehearsal_.log_dir();
  std::filesystem::create_directories(dir);
  const std::string pids = dir + "/cell.pids";
  const std::string script = write_scripted_rehearsal_cell(dir);

  ASSERT_TRUE(start_planner_services(
      {{"rehearsal_domain", rehearsal_.domain_id()},
       {"rehearsal",
        {{"start", {"/bin/sh", script}}, {"log_file", dir + "/rehearsal-cell.log"}, {"idle_stop_s", 3},
         {"start_timeout_s", 40}, {"stop_timeout_s", 10}}}}));
  ASSERT_FALSE(std::filesystem::exists(pids)) << "nothing runs on the rehearsal domain before Rehearse";

  // What the rehearsal domain sees, in its order: the world model's revisions and the task's statuses.
  std::vector<std::string> seen;
  dds::Reader<rigger_world_CellRevision> revisions(rehearsal_.participant(), protocol::world::kCell);
  dds::Reader<rigger_task_TaskStatus> statuses(rehearsal_.participant(), protocol::task::kStatus);
  rehearsal_.loop().on_data(revisions, [&] {
    revisions.take([&](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
      const auto r = world_protocol::from_wire(w);
      seen.push_back("revision " + r.sha256 + " by " + r.who);
    });
  });
  rehearsal_.loop().on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      seen.push_back("task " + dds::to_string(s.task_id));
    });
  });

  const std::string result_file = cell_.log_dir() + "/on-demand-result.json";
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(run_browser_script("test/integration/rehearsal/on_demand.mjs", result_file, 150s,
                                 {{"RECIPE", repo_file("recipes/crane_insert.json")},
                                  {"REHEARSAL_DOMAIN", std::to_string(rehearsal_.domain_id())}},
                                 &rehearsal_));
  std::printf("browser script (Rehearse, the cell started, the run, the idle stop): %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  const nlohmann::json result = nlohmann::json::parse(text_of(result_file));
  EXPECT_NE(result.at("starting_notice").get<std::string>().find("Starting the rehearsal cell of domain " +
                                                                  std::to_string(rehearsal_.domain_id())),
            std::string::npos);
  EXPECT_EQ(result.at("task_state"), "SUCCEEDED");
  EXPECT_EQ(result.at("cell_after").at("phase"), "idle");

  // The rehearsal world model took the real cell's revision before the controller heard of the task,
  // and the next one, taken while the rehearsal cell was up, before the second rehearsal.
  std::string order;
  for (const auto& s : seen) order += s + "\n";
  for (const auto& [revision, task] : std::vector<std::pair<std::string, std::string>>{
           {"real_revision", "crane-insert"}, {"second_revision", "crane-insert-again"}}) {
    const std::string applied = "revision " + result.at(revision).at("sha256").get<std::string>() + " by console:ada";
    const auto revision_at = std::find(seen.begin(), seen.end(), applied);
    const auto task_at = std::find(seen.begin(), seen.end(), "task " + task);
    ASSERT_NE(revision_at, seen.end()) << revision << "\n" << order;
    ASSERT_NE(task_at, seen.end()) << task << "\n" << order;
    EXPECT_LT(revision_at, task_at) << order;
  }

  // Every process the start command ran is gone: the script (the group's leader) and its four.
  std::istringstream listed(text_of(pids));
  std::vector<pid_t> started;
  for (pid_t pid = 0; listed >> pid;) started.push_back(pid);
  ASSERT_EQ(started.size(), 4u) << text_of(pids);
  for (const pid_t pid : started) EXPECT_NE(kill(pid, 0), 0) << "pid " << pid << " of the rehearsal cell still runs";
  const pid_t leader = result.at("cell_started").at("pid");
  EXPECT_GT(leader, 0);
  EXPECT_NE(kill(leader, 0), 0) << "the start command (pid " << leader << ") still runs";

  // The audit log: the user's Rehearse held while starting, the start by ada, ready, the idle stop.
  std::vector<nlohmann::json> audit;
  std::istringstream lines(text_of(cell_.log_dir() + "/console-audit.log"));
  for (std::string line; std::getline(lines, line);) audit.push_back(nlohmann::json::parse(line));
  const auto find = [&](const std::string& action, const std::string& result_start) {
    for (const auto& a : audit)
      if (a.value("action", "") == action && a.value("result", "").rfind(result_start, 0) == 0) return a;
    return nlohmann::json();
  };
  const auto started_entry = find("rehearsal_cell", "started (pid " + std::to_string(leader));
  ASSERT_FALSE(started_entry.is_null()) << text_of(cell_.log_dir() + "/console-audit.log");
  EXPECT_EQ(started_entry.value("by", ""), "console:ada");
  EXPECT_FALSE(find("rehearsal_cell", "ready after").is_null());
  EXPECT_FALSE(find("rehearsal_cell", "stopping (pid " + std::to_string(leader) + "): idle for").is_null());
  EXPECT_FALSE(find("rehearsal_cell", "stopped (pid " + std::to_string(leader)).is_null());
  EXPECT_FALSE(find("rehearse", "held: started the rehearsal cell").is_null());
  EXPECT_FALSE(find("rehearse", "sent to rehearsal domain").is_null());
}

}  // namespace
}  // namespace rigger::testing
