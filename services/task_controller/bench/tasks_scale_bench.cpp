// How the controller's cost grows with the work it carries: 1, 10 and 50 tasks running at once on one
// controller, their leaves on one executor, and the same with one executor per task (10 and 50
// executors). Real processes on a private domain, one host. Each task is Repeat(Sequence[Step, Step])
// of a skill that succeeds `period_ms` after its START and claims nothing (so the tasks never wait for
// each other). Printed per point: the hand-over (a leaf's SUCCESS written -> the next START received by
// its executor, both from the executors' receipt traces, paired per task), p50 and p99; the controller's
// CPU per task; the discovery of the cell (every process started -> all READY); and whether each curve
// is flat (largest / smallest <= 1.2), linear or worse. Each point is run twice, in cells of their own:
// by the controller, and by the relay floor (task_controller_relay_floor --pattern tasks: the same STARTs
// to the same executors, nothing else), so that every hand-over figure stands next to what the hop alone
// costs with the same burst of events. Run on demand, not a test.
//
//   build/bench/task_controller_tasks_scale_bench [--hand-overs 200] [--period-ms 10]
//
// Exit 0 when every task succeeded and every hand-over paired; the verdicts are figures.
#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>
#include <thread>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "live_reaction.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/testing/process.hpp"

namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using rigger::bench::percentile;

constexpr int kEventSuccess = 100;  // scripted_executor's receipt kind of a SUCCESS it wrote

struct Point {
  int tasks = 0, executors = 0;
  bool ok = false;
  std::vector<double> hand_over_us;
  std::vector<double> relay_us;  ///< the same hand-overs done by the relay floor
  double cpu_per_task = 0;  ///< controller CPU seconds per wall second, per task
  double discovery_s = 0;
  double wall_s = 0;
};

/// A library of `n` skills Step0..Step<n-1>: no parameters, no resources, no conditions.
json step_library(int n) {
  json skills = json::array();
  for (int i = 0; i < n; ++i)
    skills.push_back({{"name", "Step" + std::to_string(i)},
                      {"kind", "skill"},
                      {"description", "a scripted step of the bench"},
                      {"params", json::array()},
                      {"resources", json::array()}});
  return {{"library_version", 1}, {"skills", skills}};
}

/// The hand-overs of the executors' receipt traces, paired per task: each SUCCESS an executor wrote, then the
/// next START it took for that task. False (and why on stderr) when one is unpaired or missing.
bool pair_hand_overs(const std::string& dir, int tasks, int executors, int starts_per_task, std::vector<double>& out) {
  std::map<std::string, std::vector<rigger::bench::Receipt>> by_task;
  for (int e = 0; e < executors; ++e)
    for (rigger::bench::Receipt& r : rigger::bench::read_receipts(dir + "/ex" + std::to_string(e) + ".tsv"))
      if (r.kind == kEventSuccess || r.kind == rigger_skill_SKILL_START) by_task[r.task_id].push_back(std::move(r));
  std::size_t unpaired = 0;
  for (auto& [task, rows] : by_task) {
    std::sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.stamp_wall_ns < b.stamp_wall_ns; });
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].kind != kEventSuccess) continue;
      if (i + 1 < rows.size() && rows[i + 1].kind == rigger_skill_SKILL_START)
        out.push_back((rows[i + 1].woke_wall_ns - rows[i].stamp_wall_ns) / 1000.0);
      else if (i + 1 < rows.size())
        ++unpaired;
    }
  }
  const std::size_t expected = static_cast<std::size_t>(tasks) * (starts_per_task - 1);
  if (unpaired != 0 || out.size() != expected) {
    std::fprintf(stderr, "%zu hand-overs paired of %zu, %zu SUCCESS not followed by a START (%s)\n", out.size(),
                 expected, unpaired, dir.c_str());
    return false;
  }
  return true;
}

/// The executors of a point, each with its receipt trace; their ids, or empty when the cell did not start.
std::vector<std::string> start_executors(rigger::testing::Cell& cell, int executors, int period_ms) {
  const std::string dir = cell.log_dir();
  const std::string library = rigger::bench::write_file(dir + "/library.json", step_library(executors).dump());
  std::vector<std::string> ids;
  for (int e = 0; e < executors; ++e) {
    const std::string id = "ex" + std::to_string(e);
    cell.start(id, "scripted_executor",
               {"--id", id, "--log-level", "warn", "--config",
                rigger::bench::write_file(dir + "/" + id + ".json",
                                          json{{"library_file", library},
                                               {"skills", {"Step" + std::to_string(e)}},
                                               {"default", {{"mode", "succeed"}, {"delay_s", period_ms / 1000.0}}},
                                               {"receipt_trace_path", dir + "/" + id + ".tsv"}}
                                              .dump())});
    ids.push_back(id);
  }
  return ids;
}

/// The point's hand-overs done by the relay floor, in a cell of its own with the same executors.
bool run_relay(int tasks, int executors, int starts_per_task, int period_ms, Point& p) {
  rigger::testing::Cell cell("relay-tasks-" + std::to_string(tasks) + "-executors-" + std::to_string(executors));
  const std::vector<std::string> ids = start_executors(cell, executors, period_ms);
  if (!cell.wait_ready(ids, 120s)) {
    std::fprintf(stderr, "the relay's executors did not become ready\n%s", cell.logs().c_str());
    return false;
  }
  auto& relay = cell.start("relay", "task_controller_relay_floor",
                           {"--pattern", "tasks", "--tasks", std::to_string(tasks), "--executors",
                            std::to_string(executors), "--trials", std::to_string(starts_per_task), "--trace",
                            cell.log_dir() + "/relay.tsv"});
  // A command the relay lost stalls it (it writes nothing again once its executors answered).
  const auto budget = std::chrono::milliseconds(60000 + 4 * starts_per_task * (period_ms + 20));
  if (!cell.wait_until([&] { return !relay.running(); }, budget)) {
    std::fprintf(stderr, "the relay floor did not finish (a lost command stalls it)\n%s", cell.logs().c_str());
    return false;
  }
  const auto status = relay.wait(1s);
  if (!status || !status->ok()) {
    std::fprintf(stderr, "the relay floor failed\n%s", cell.logs().c_str());
    return false;
  }
  cell.stop_all();  // the executors write their receipt traces as they stop
  return pair_hand_overs(cell.log_dir(), tasks, executors, starts_per_task, p.relay_us);
}

/// Runs `tasks` tasks of `hand_overs` hand-overs each at once, on `executors` executors; ok false on failure.
bool run_point(int tasks, int executors, int hand_overs, int period_ms, Point& p) {
  p.tasks = tasks;
  p.executors = executors;
  rigger::testing::Cell cell("tasks-" + std::to_string(tasks) + "-executors-" + std::to_string(executors));
  const std::string dir = cell.log_dir();
  const auto started = Clock::now();
  auto& tc = cell.start("tc", "task_controller",
                        {"--id", "tc", "--log-level", "warn", "--config",
                         rigger::bench::write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal.sqlite"},
                                                                                  {"executor_wait_s", 30}}
                                                                                 .dump())});
  std::vector<std::string> ids = start_executors(cell, executors, period_ms);
  ids.push_back("tc");
  if (!cell.wait_ready(ids, 120s)) {
    std::fprintf(stderr, "the cell did not become ready\n%s", cell.logs().c_str());
    return false;
  }
  p.discovery_s = std::chrono::duration<double>(Clock::now() - started).count();
  rigger::bench::Observer obs(cell);
  if (!obs.recipes.wait_for_readers(1, 10s) || !obs.statuses.wait_for_writers(1, 10s)) {
    std::fprintf(stderr, "the task endpoints did not match\n");
    return false;
  }
  std::map<std::string, int> final_state;
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (s.state == rigger_task_TASK_SUCCEEDED || s.state == rigger_task_TASK_FAILED ||
          s.state == rigger_task_TASK_REJECTED || s.state == rigger_task_TASK_CANCELED)
        final_state[rigger::dds::to_string(s.task_id)] = s.state;
    });
  });
  const double cpu_before = rigger::testing::cpu_seconds(tc.pid());
  const auto t0 = Clock::now();
  for (int k = 0; k < tasks; ++k) {
    const json step = {{"type", "Skill"}, {"skill", "Step" + std::to_string(k % executors)}};
    obs.submit("t" + std::to_string(k),
               {{"recipe_version", 1},
                {"task_id", "t" + std::to_string(k)},
                {"root", {{"type", "Repeat"},
                          {"repetitions", std::max(1, (hand_overs + 1) / 2)},
                          {"child", {{"type", "Sequence"}, {"children", {step, step}}}}}}});
  }
  const auto budget = std::chrono::milliseconds(60000 + 4 * hand_overs * (period_ms + 20));
  if (!cell.wait_until([&] { return static_cast<int>(final_state.size()) == tasks; }, budget)) {
    std::fprintf(stderr, "%zu of %d tasks ended\n", final_state.size(), tasks);
    return false;
  }
  p.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  p.cpu_per_task = (rigger::testing::cpu_seconds(tc.pid()) - cpu_before) / p.wall_s / tasks;
  for (const auto& [task, state] : final_state)
    if (state != rigger_task_TASK_SUCCEEDED) {
      std::fprintf(stderr, "task %s ended in state %d\n", task.c_str(), state);
      return false;
    }
  cell.stop_all();  // the executors write their receipt traces as they stop

  const int starts_per_task = 2 * std::max(1, (hand_overs + 1) / 2);
  return pair_hand_overs(dir, tasks, executors, starts_per_task, p.hand_over_us) &&
         run_relay(tasks, executors, starts_per_task, period_ms, p);
}

/// The points of `--points` ("1x1,10x1": tasks x executors), or the default plan for this machine.
std::vector<std::pair<int, int>> plan_of(int argc, char** argv) {
  std::string text = rigger::bench::string_option(argc, argv, "--points", "");
  if (text.empty()) {
    // 50 executor processes stall their own liveliness on a small machine while 51 participants discover
    // each other (decision 0022): the controller then rightly fails their leaves. Asked for by --points.
    text = std::thread::hardware_concurrency() >= 8 ? "1x1,10x1,50x1,10x10,50x50" : "1x1,10x1,50x1,10x10";
    if (std::thread::hardware_concurrency() < 8)
      std::printf("50 tasks on 50 executors: not in the plan on %u cores (--points 50x50 runs it)\n",
                  std::thread::hardware_concurrency());
  }
  std::vector<std::pair<int, int>> plan;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    int tasks = 0, executors = 0;
    if (std::sscanf(item.c_str(), "%dx%d", &tasks, &executors) != 2 || tasks < 1 || executors < 1 || executors > tasks) {
      std::fprintf(stderr, "--points: \"%s\" is not TASKSxEXECUTORS with 1 <= executors <= tasks\n", item.c_str());
      std::exit(2);
    }
    plan.emplace_back(tasks, executors);
  }
  return plan;
}

std::string verdict(const std::vector<Point>& points, double (*figure)(const Point&), const char* what) {
  std::string out;
  for (std::size_t i = 1; i < points.size(); ++i)
    out += std::string(what) + ", " + std::to_string(points[0].tasks) + "x" + std::to_string(points[0].executors) +
           " -> " + std::to_string(points[i].tasks) + "x" + std::to_string(points[i].executors) + ": " +
           rigger::bench::growth_verdict(figure(points[0]), figure(points[i]), points[i].tasks / points[0].tasks) +
           "\n";
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const int hand_overs = rigger::bench::int_option(argc, argv, "--hand-overs", 200);
  const int period_ms = std::max(1, rigger::bench::int_option(argc, argv, "--period-ms", 10));
  const std::vector<std::pair<int, int>> plan = plan_of(argc, argv);
  std::vector<Point> points;
  for (const auto& [tasks, executors] : plan) {
    Point p;
    p.ok = run_point(tasks, executors, hand_overs, period_ms, p);
    if (!p.ok) {
      std::printf("%3d tasks, %2d executors: FAILED (why: above)\n", tasks, executors);
      return 1;
    }
    std::printf("%3d tasks, %2d executors: hand-over p50 %7.1f p99 %8.1f us (relay floor %7.1f / %8.1f), "
                "controller CPU %.4f per task, discovery %.2f s\n",
                tasks, executors, percentile(p.hand_over_us, 0.5), percentile(p.hand_over_us, 0.99),
                percentile(p.relay_us, 0.5), percentile(p.relay_us, 0.99), p.cpu_per_task, p.discovery_s);
    std::fflush(stdout);
    points.push_back(std::move(p));
  }
  std::printf("\nHand-over (a leaf's SUCCESS written -> the next START received, us), %d per task, %d ms leaves, "
              "one host; the relay floor did the same hand-overs to the same executors.\n\n"
              "%6s %10s %9s %9s %9s %9s %8s %8s %16s %12s\n",
              hand_overs, period_ms, "tasks", "executors", "p50", "p99", "relay p50", "relay p99", "p50 x", "p99 x",
              "CPU s/s per task", "discovery s");
  for (const Point& p : points)
    std::printf("%6d %10d %9.1f %9.1f %9.1f %9.1f %8.2f %8.2f %16.4f %12.2f\n", p.tasks, p.executors,
                percentile(p.hand_over_us, 0.5), percentile(p.hand_over_us, 0.99), percentile(p.relay_us, 0.5),
                percentile(p.relay_us, 0.99), percentile(p.hand_over_us, 0.5) / percentile(p.relay_us, 0.5),
                percentile(p.hand_over_us, 0.99) / percentile(p.relay_us, 0.99), p.cpu_per_task, p.discovery_s);
  std::printf("\n%s%s%s%s",
              verdict(points, [](const Point& p) { return percentile(p.hand_over_us, 0.99); }, "controller p99").c_str(),
              verdict(points, [](const Point& p) { return percentile(p.relay_us, 0.99); }, "relay floor p99").c_str(),
              verdict(points, [](const Point& p) { return percentile(p.hand_over_us, 0.99) / percentile(p.relay_us, 0.99); },
                      "controller / relay p99").c_str(),
              verdict(points, [](const Point& p) { return p.cpu_per_task; }, "controller CPU per task").c_str());

  rigger::performance::Report report(
      "task_controller_tasks_scale_bench",
      "Hand-over (SUCCESS written -> next START received) with 1, 10 and 50 tasks at once on one controller, on "
      "one executor and on one executor per task, " + std::to_string(hand_overs) + " hand-overs per task, " +
          std::to_string(period_ms) + " ms leaves; each point next to the relay floor doing the same hand-overs");
  for (const Point& p : points) {
    const std::string label = std::to_string(p.tasks) + " tasks, " + std::to_string(p.executors) + " executors";
    rigger::bench::add_quantiles(report, "hand-over, " + label, rigger::bench::quantiles(p.hand_over_us), "us",
                                 "relay floor, " + label, rigger::bench::quantiles(p.relay_us));
    report.add({"controller CPU per task, " + label, p.cpu_per_task, "CPU s/s", "", 0});
    report.add({"discovery (started -> all READY), " + label, p.discovery_s, "s", "", 0});
  }
  return rigger::performance::save_for_main(report);
}
