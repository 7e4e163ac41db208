// The task controller as a real process, with scripted executors, on a private domain; run on
// demand, not a test. Prints:
//
//  1. Reaction latency (issue 3): a monitor's FAILURE written → the sibling skill's SHUTDOWN received,
//     across three processes (monitor executor → controller → skill executor), p50/p90/p99, with the
//     journal as deployed (journal_sync normal) and with journal_sync full. Clocks: the FAILURE's and
//     SHUTDOWN's stamps are their writers' wall clocks; "received" is this process's wall clock when
//     the SHUTDOWN arrives (it subscribes like the skill executor, through the same path); the skill
//     executor's STOPPED stamp bounds its own receipt from above. One host, one clock.
//     Next to ddsperf ping/pong one-way latency (half its round trip) at the same rate, measured in
//     the same run with ddsperf's waitset and with its listener triggering.
//     Where the time goes, per stage, from the controller's own stage trace (its stage_trace_path, a file
//     it writes when it stops; steady-clock instants of one host): FAILURE written → controller woke
//     (DDS, wall clocks) → SHUTDOWN handed to DDS (take, engine) → written → engine done → journal rows
//     and node statuses flushed; then SHUTDOWN written → received here (DDS, wall clocks).
//  2. Idle CPU: CPU seconds per wall second (/proc/PID/stat utime+stime) of the controller with no
//     task, with 1 running leaf and with 100 running leaves (1 skill + 99 monitors in a Parallel),
//     each over --idle-seconds (default 60, the "60 s skill"), next to an idle ddsperf
//     participant (ddsperf pong, nobody pinging) and an idle echo service over the same windows.
//     Wake-ups per wall second of the controller over the same windows: its work loop's thread (the
//     main thread: one voluntary context switch per waitset wait that blocks) and all its threads
//     (Cyclone's included), from voluntary_ctxt_switches in /proc/PID/task/TID/status.
//
//   build/bench/task_controller_live_bench [--trials 1000] [--period-ms 10] [--idle-seconds 60]
//                                          [--ddsperf-seconds 10]
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/executor/executor_endpoint.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"
#include "task_controller_node.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using nlohmann::json;
namespace tc = rigger::task_controller;
namespace dds = rigger::dds;

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

std::int64_t wire_ns(const rigger_geometry_Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000000LL + t.nanosec;
}

struct Observer {
  explicit Observer(rigger::testing::Cell& cell)
      : recipes(cell.participant(), rigger::protocol::task::kRecipe),
        task_commands(cell.participant(), rigger::protocol::task::kCommand),
        statuses(cell.participant(), rigger::protocol::task::kStatus),
        commands(cell.participant(), rigger::protocol::skill::kCommand),
        events(cell.participant(), rigger::protocol::skill::kEvent) {}

  void submit(const std::string& task_id, const json& recipe) {
    rigger_task_Recipe r{};
    const std::string text = recipe.dump(), submitter = "bench";
    r.task_id = dds::wire_string(task_id);
    r.recipe_json = dds::wire_string(text);
    r.submitter = dds::wire_string(submitter);
    r.stamp = dds::wire_now();
    recipes.write(r);
  }
  void cancel(const std::string& task_id) {
    rigger_task_TaskCommand c{};
    const std::string issuer = "bench", reason = "bench done";
    c.task_id = dds::wire_string(task_id);
    c.kind = rigger_task_TASK_CANCEL;
    c.reason = dds::wire_string(reason);
    c.issuer = dds::wire_string(issuer);
    c.seq = ++seq;
    c.stamp = dds::wire_now();
    task_commands.write(c);
  }

  dds::Writer<rigger_task_Recipe> recipes;
  dds::Writer<rigger_task_TaskCommand> task_commands;
  dds::Reader<rigger_task_TaskStatus> statuses;
  dds::Reader<rigger_skill_SkillCommand> commands;
  dds::Reader<rigger_skill_SkillEvent> events;
  std::uint64_t seq = 0;
};

struct Reaction {
  // Per trial, from the monitor's FAILURE (its executor's stamp) to:
  std::vector<double> shutdown_written_us;   ///< the controller's SHUTDOWN stamp (1 hop + handling)
  std::vector<double> shutdown_received_us;  ///< this process receiving that SHUTDOWN (2 hops + handling)
  std::vector<double> stopped_written_us;    ///< the skill executor's STOPPED stamp (bounds its receipt)
  // Per trial, one stage each (the controller's stage trace; they add up to shutdown_received_us but
  // for the clock reads between them):
  std::vector<double> to_woke_us;         ///< FAILURE written → controller's handler woke (DDS, 1 hop)
  std::vector<double> to_writing_us;      ///< woke → SHUTDOWN handed to DDS (take, engine until the write)
  std::vector<double> writing_us;         ///< the SHUTDOWN's write call
  std::vector<double> to_engine_us;       ///< SHUTDOWN written → engine returned
  std::vector<double> to_flushed_us;      ///< engine returned → journal rows and node statuses written
  std::vector<double> command_to_seen_us;  ///< SHUTDOWN stamped → received here (DDS, 1 hop)
  double trials_per_s = 0;
  bool ok = false;
};

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

/// The paper's pattern, repeated: Repeat(trials, ForceSuccess(Parallel(1, 1)[skill, monitor])). The
/// skill (Localize on executor "skills") runs until shut down; the monitor (TimerMonitor on executor
/// "monitors", another process) fails `period_ms` after its START. Three processes take part — the
/// monitor's executor, the controller, the skill's executor — and this one watches the topics.
Reaction measure_reaction(const std::string& journal_sync, int trials, int period_ms) {
  Reaction out;
  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  const std::string trace_path = dir + "/stages-" + journal_sync + ".tsv";
  cell.start("tc", "task_controller",
             {"--id", "tc", "--log-level", "warn", "--config",
              write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal-" + journal_sync + ".sqlite"},
                                                {"journal_sync", journal_sync},
                                                {"stage_trace_path", trace_path}}
                                               .dump())});
  cell.start("skills", "scripted_executor",
             {"--id", "skills", "--log-level", "warn", "--config",
              write_file(dir + "/skills.json", json{{"skills", {"Localize"}}, {"default", {{"mode", "run"}}}}.dump())});
  cell.start("monitors", "scripted_executor",
             {"--id", "monitors", "--log-level", "warn", "--config",
              write_file(dir + "/monitors.json",
                         json{{"skills", {"TimerMonitor"}},
                              {"behaviours",
                               {{"TimerMonitor", {{"mode", "fail"}, {"delay_s", period_ms / 1000.0}, {"code", "BENCH"}}}}}}
                             .dump())});
  if (!cell.wait_ready({"tc", "skills", "monitors"}, 30s)) {
    std::fprintf(stderr, "services did not become ready\n%s", cell.logs().c_str());
    return out;
  }
  Observer obs(cell);
  if (!obs.recipes.wait_for_readers(1, 10s)) return out;
  // Trials run one after the other (the next starts after the skill STOPPED), so the i-th FAILURE,
  // SHUTDOWN and STOPPED belong to trial i.
  std::vector<std::int64_t> failure_ns, shutdown_stamp_ns, shutdown_seen_ns, stopped_ns;
  bool done = false;
  int final_state = -1;
  cell.loop().on_data(obs.events, [&] {
    obs.events.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
      const std::string executor = dds::to_string(e.executor_id);
      if (executor == "monitors" && e.kind == rigger_skill_SKILL_EVENT_FAILURE) failure_ns.push_back(wire_ns(e.stamp));
      if (executor == "skills" && e.kind == rigger_skill_SKILL_EVENT_STOPPED) stopped_ns.push_back(wire_ns(e.stamp));
    });
  });
  cell.loop().on_data(obs.commands, [&] {
    const std::int64_t seen = wire_ns(dds::wire_now());
    obs.commands.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
      if (c.kind != rigger_skill_SKILL_SHUTDOWN || dds::to_string(c.executor_id) != "skills") return;
      shutdown_stamp_ns.push_back(wire_ns(c.stamp));
      shutdown_seen_ns.push_back(seen);
    });
  });
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) == "reaction" && terminal(s.state)) {
        done = true;
        final_state = s.state;
      }
    });
  });
  const json parallel = {
      {"type", "Parallel"},
      {"success_threshold", 1},
      {"failure_threshold", 1},
      {"children",
       {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
        {{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 3600}}}}}}};
  const json root = {{"type", "Repeat"},
                     {"repetitions", trials},
                     {"child", {{"type", "ForceSuccess"}, {"child", parallel}}}};
  const auto t0 = Clock::now();
  obs.submit("reaction", {{"recipe_version", 1}, {"task_id", "reaction"}, {"root", root}});
  if (!cell.wait_until([&] { return done; }, std::chrono::milliseconds(30000 + trials * (period_ms + 20)))) {
    std::fprintf(stderr, "the reaction recipe did not finish\n");
    return out;
  }
  out.trials_per_s = trials / std::chrono::duration<double>(Clock::now() - t0).count();
  if (final_state != rigger_task_TASK_SUCCEEDED) {
    std::fprintf(stderr, "the reaction recipe ended in state %d\n%s", final_state, cell.logs().c_str());
    return out;
  }
  cell.stop_all();
  const std::size_t n = failure_ns.size();
  if (n == 0 || shutdown_stamp_ns.size() != n || stopped_ns.size() != n) {
    std::fprintf(stderr, "unpaired events: %zu FAILURE, %zu SHUTDOWN, %zu STOPPED\n", n, shutdown_stamp_ns.size(),
                 stopped_ns.size());
    return out;
  }
  for (std::size_t i = 0; i < n; ++i) {
    out.shutdown_written_us.push_back(static_cast<double>(shutdown_stamp_ns[i] - failure_ns[i]) / 1000.0);
    out.shutdown_received_us.push_back(static_cast<double>(shutdown_seen_ns[i] - failure_ns[i]) / 1000.0);
    out.stopped_written_us.push_back(static_cast<double>(stopped_ns[i] - failure_ns[i]) / 1000.0);
    out.command_to_seen_us.push_back(static_cast<double>(shutdown_seen_ns[i] - shutdown_stamp_ns[i]) / 1000.0);
  }
  // The controller wrote its trace when it stopped (stop_all waited for it). A trial's FAILURE is the
  // record with its stamp.
  std::map<std::int64_t, tc::StageRecord> traced;
  for (auto& r : tc::StageTrace::read(trace_path))
    if (r.executor_id == "monitors" && r.kind == "FAILURE") traced.emplace(r.stamp_wall_ns, std::move(r));
  const auto us = [](std::int64_t from, std::int64_t to) { return static_cast<double>(to - from) / 1000.0; };
  for (std::size_t i = 0; i < n; ++i) {
    auto it = traced.find(failure_ns[i]);
    if (it == traced.end() || it->second.command_ns == 0 || it->second.flushed_ns == 0) continue;
    const auto& r = it->second;
    out.to_woke_us.push_back(us(r.stamp_wall_ns, r.woke_wall_ns));
    out.to_writing_us.push_back(us(r.woke_ns, r.writing_ns));
    out.writing_us.push_back(us(r.writing_ns, r.command_ns));
    out.to_engine_us.push_back(us(r.command_ns, r.engine_ns));
    out.to_flushed_us.push_back(us(r.engine_ns, r.flushed_ns));
  }
  if (out.to_woke_us.size() != n)
    std::fprintf(stderr, "stage trace: %zu of %zu trials traced (%s)\n", out.to_woke_us.size(), n, trace_path.c_str());
  out.ok = true;
  return out;
}

void print_row(const char* label, const std::vector<double>& v) {
  using rigger::bench::percentile;
  std::printf("%-58s %9.1f %9.1f %9.1f %7zu\n", label, percentile(v, 0.5), percentile(v, 0.9), percentile(v, 0.99),
              v.size());
}

/// CPU seconds per wall second of each pid over `seconds` (the loop runs meanwhile, handling nothing),
/// then the first pid's wake-ups per wall second: its main thread's, all its threads'.
std::vector<double> cpu_share(rigger::testing::Cell& cell, const std::vector<pid_t>& pids, int seconds) {
  return rigger::bench::cpu_share(pids, [&] {
    bool over = false;
    const auto timer = cell.loop().after(std::chrono::seconds(seconds), [&] { over = true; });
    cell.wait_until([&] { return over; }, std::chrono::seconds(seconds + 5));
    cell.loop().cancel(timer);
  });
}

int measure_idle(int seconds) {
  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  auto& tcp = cell.start("tc", "task_controller",
                         {"--id", "tc", "--log-level", "warn", "--config",
                          write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal-idle.sqlite"}}.dump())});
  auto& exec =
      cell.start("exec", "scripted_executor",
                 {"--id", "exec", "--log-level", "warn", "--config",
                  write_file(dir + "/exec.json",
                             json{{"skills", {"Localize", "TimerMonitor"}}, {"default", {{"mode", "run"}}}}.dump())});
  auto& echo = cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
  // An idle ddsperf participant on the same domain and configuration: pong, with nobody pinging.
  auto& ddsperf = cell.start("ddsperf", "/usr/bin/ddsperf",
                             {"-i", std::to_string(cell.domain_id()), "-D", std::to_string(4 * seconds + 60), "pong"},
                             false);
  if (!cell.wait_ready({"tc", "exec", "echo"}, 30s)) {
    std::fprintf(stderr, "services did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  Observer obs(cell);
  if (!obs.recipes.wait_for_readers(1, 10s)) return 1;
  std::size_t starts = 0;
  cell.loop().on_data(obs.commands, [&] {
    obs.commands.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
      if (c.kind == rigger_skill_SKILL_START) ++starts;
    });
  });
  std::map<std::string, int> state;
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take(
        [&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) { state[dds::to_string(s.task_id)] = s.state; });
  });
  const std::vector<pid_t> pids = {tcp.pid(), ddsperf.pid(), echo.pid(), exec.pid()};
  std::printf("\nIdle CPU (CPU s per wall s, /proc/PID/stat utime+stime over %d s each)\n", seconds);
  std::printf("%-20s %10s %10s %8s %10s %10s %14s %14s\n", "", "controller", "ddsperf", "ratio", "echo", "scripted",
              "tc loop wk/s", "tc all wk/s");
  auto row = [&](const char* label, const std::vector<double>& s) {
    std::printf("%-20s %10.4f %10.4f %7.2fx %10.4f %10.4f %14.1f %14.1f\n", label, s[0], s[1],
                s[0] / std::max(1e-9, s[1]), s[2], s[3], s[4], s[5]);
  };
  row("no task", cpu_share(cell, pids, seconds));

  const json skill = {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}};
  obs.submit("one", {{"recipe_version", 1}, {"task_id", "one"}, {"root", skill}});
  if (!cell.wait_until([&] { return starts >= 1; }, 20s)) {
    std::fprintf(stderr, "task one did not start\n%s", cell.logs().c_str());
    return 1;
  }
  row("1 running leaf", cpu_share(cell, pids, seconds));
  obs.cancel("one");
  if (!cell.wait_until([&] { return state["one"] == rigger_task_TASK_CANCELED; }, 20s)) return 1;

  json children = json::array({skill});
  for (int i = 0; i < 99; ++i)
    children.push_back({{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 3600}}}});
  obs.submit(
      "hundred",
      {{"recipe_version", 1},
       {"task_id", "hundred"},
       {"root", {{"type", "Parallel"}, {"success_threshold", 1}, {"failure_threshold", 1}, {"children", children}}}});
  if (!cell.wait_until([&] { return starts >= 101; }, 30s)) {
    std::fprintf(stderr, "task hundred did not start its 100 leaves (%zu starts)\n%s", starts, cell.logs().c_str());
    return 1;
  }
  row("100 running leaves", cpu_share(cell, pids, seconds));
  obs.cancel("hundred");
  cell.wait_until([&] { return state["hundred"] == rigger_task_TASK_CANCELED; }, 20s);
  cell.stop("ddsperf", SIGINT, 5s);
  cell.stop_all();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  using rigger::bench::percentile;
  const int trials = int_option(argc, argv, "--trials", 1000);
  const int period_ms = std::max(1, int_option(argc, argv, "--period-ms", 10));
  const int idle_seconds = int_option(argc, argv, "--idle-seconds", 60);
  const int ddsperf_seconds = int_option(argc, argv, "--ddsperf-seconds", 10);

  const Reaction normal = measure_reaction("normal", trials, period_ms);
  const Reaction full = measure_reaction("full", std::max(1, trials / 5), period_ms);
  if (!normal.ok || !full.ok) return 1;
  // ddsperf at the rate the trials ran (rounded), on the same payload order (a SkillEvent is ~150 B).
  const int rate_hz = std::max(1, static_cast<int>(normal.trials_per_s + 0.5));
  rigger::bench::DdsperfLatency waitset, listener;
  {
    rigger::testing::DomainLease lease;
    waitset = rigger::bench::run_ddsperf_pingpong(lease.id(), rate_hz, 128, ddsperf_seconds, true);
    listener = rigger::bench::run_ddsperf_pingpong(lease.id(), rate_hz, 128, ddsperf_seconds, false);
  }
  if (waitset.count == 0 || listener.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n%s\n", waitset.raw.c_str(), listener.raw.c_str());
    return 1;
  }
  std::printf("Reaction: monitor FAILURE written -> sibling SHUTDOWN, Repeat(ForceSuccess(Parallel(1,1)[skill, "
              "monitor])), %d trials at %.0f per s\n",
              trials, normal.trials_per_s);
  std::printf("%-62s %9s %9s %9s %7s\n", "", "p50 us", "p90 us", "p99 us", "n");
  print_row("SHUTDOWN received (2 hops + controller), journal normal", normal.shutdown_received_us);
  print_row("  SHUTDOWN written by the controller (1 hop + handling)", normal.shutdown_written_us);
  print_row("  STOPPED written by the skill executor (bounds its receipt)", normal.stopped_written_us);
  print_row("SHUTDOWN received, journal_sync full", full.shutdown_received_us);
  const auto stages = [](const char* label, const Reaction& r) {
    std::printf("Per stage, journal %s (controller's stage trace, %zu trials):\n", label, r.to_woke_us.size());
    print_row("  1 FAILURE written -> controller woke (DDS, 1 hop)", r.to_woke_us);
    print_row("  2 woke -> SHUTDOWN handed to DDS (take, engine)", r.to_writing_us);
    print_row("  3 SHUTDOWN write call (dds_write returns)", r.writing_us);
    print_row("  4 SHUTDOWN written -> engine done", r.to_engine_us);
    print_row("  5 engine done -> journal rows + node status flushed", r.to_flushed_us);
    print_row("  6 SHUTDOWN stamped -> received here (DDS, 1 hop)", r.command_to_seen_us);
  };
  stages("normal", normal);
  stages("sync full", full);
  const auto ref_row = [](const char* label, const rigger::bench::DdsperfLatency& r) {
    std::printf("%-62s %9.1f %9.1f %9.1f %7llu\n", label, r.p50_us / 2, r.p90_us / 2, r.p99_us / 2,
                static_cast<unsigned long long>(r.count));
  };
  std::printf("ddsperf one-way (half the round trip), 128 B, %d Hz:\n", rate_hz);
  ref_row("  ddsperf waitset triggering (as rigger's event loop)", waitset);
  ref_row("  ddsperf listener triggering (ddsperf's default)", listener);
  const double p50 = percentile(normal.shutdown_received_us, 0.5);
  const double p99 = percentile(normal.shutdown_received_us, 0.99);
  std::printf("p50 / one-way: %.2fx (waitset) %.2fx (listener), target <= 3x; p99 %.0f us, target <= 1000 us\n",
              p50 / (waitset.p50_us / 2), p50 / (listener.p50_us / 2), p99);
  return measure_idle(idle_seconds);
}
