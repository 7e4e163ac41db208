// The task controller as a real process, with scripted executors, on a private domain; run on
// demand, not a test. Prints:
//
//  1. Reaction latency (issues 3 and 19), across three processes (an executor → the controller → an
//     executor), p50/p90/p99:
//     A. a monitor's FAILURE written → the sibling skill's SHUTDOWN received by the skill's executor
//        (Repeat(ForceSuccess(Parallel(1, 1)[skill, monitor]))), with the journal as deployed
//        (journal_sync normal) and with journal_sync full;
//     B. a leaf's SUCCESS written → the next leaf's START received by its executor
//        (Repeat(Sequence[skill, skill])).
//     "Received" is the instant the executor's event loop woke for the command (scripted_executor's
//     receipt_trace_path); the event's stamp is its writer's wall clock, as recorded in the controller's
//     stage trace. This process reads neither skill events nor skill commands: it adds no reader to the
//     path it measures. One host, one clock.
//     Next to ddsperf ping/pong one-way latency (half its round trip) at the same rate, measured in
//     the same run with ddsperf's waitset and with its listener triggering.
//     Where the time goes, per stage, from the controller's own stage trace (its stage_trace_path, a file
//     it writes when it stops; steady-clock instants of one host): event written → controller woke
//     (DDS, wall clocks) → command handed to DDS (take, engine) → written → engine done → journal rows
//     and node statuses flushed; then command written → the executor woke (DDS, wall clocks).
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
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "rigger/dds/partitions.hpp"
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

/// What the bench writes and reads on the task topics. It reads neither skill commands nor skill events:
/// every timing comes from the processes that take part (the controller's stage trace, the skill
/// executor's receipt trace), so that the bench adds no reader to the path it measures (each reader a
/// sample goes to is one more send and one more woken process on a 2-core machine).
struct Observer {
  explicit Observer(rigger::testing::Cell& cell)
      : recipes(cell.participant(), rigger::protocol::task::kRecipe),
        task_commands(cell.participant(), rigger::protocol::task::kCommand),
        statuses(cell.participant(), rigger::protocol::task::kStatus) {}

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
  std::uint64_t seq = 0;
};

/// One line of scripted_executor's receipt trace.
struct Receipt {
  std::string executor_id, task_id, node_id;
  int kind = 0;
  std::int64_t stamp_wall_ns = 0, woke_wall_ns = 0;
};

std::vector<Receipt> read_receipts(const std::string& path) {
  std::vector<Receipt> out;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return out;  // the header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    Receipt r;
    std::string kind;
    if (std::getline(fields, r.executor_id, '\t') && std::getline(fields, kind, '\t') &&
        std::getline(fields, r.task_id, '\t') && std::getline(fields, r.node_id, '\t') &&
        fields >> r.stamp_wall_ns >> r.woke_wall_ns) {
      r.kind = std::stoi(kind);
      out.push_back(std::move(r));
    }
  }
  return out;
}

struct Reaction {
  // Per trial, from the event that causes the command (its executor's stamp) to:
  std::vector<double> command_written_us;   ///< the controller's command stamp (1 hop + handling)
  std::vector<double> command_received_us;  ///< the executor's loop woke for it (2 hops + handling)
  std::vector<double> stopped_written_us;   ///< the skill executor's STOPPED stamp (SHUTDOWN trials)
  // Per trial, one stage each (the controller's stage trace; they add up to command_received_us but
  // for the clock reads between them):
  std::vector<double> to_woke_us;          ///< event written → controller's handler woke (DDS, 1 hop)
  std::vector<double> to_writing_us;       ///< woke → command handed to DDS (take, engine until the write)
  std::vector<double> writing_us;          ///< the command's write call
  std::vector<double> to_engine_us;        ///< command written → engine returned
  std::vector<double> to_flushed_us;       ///< engine returned → journal rows and node statuses written
  std::vector<double> command_to_seen_us;  ///< command stamped → executor woke (DDS, 1 hop)
  double trials_per_s = 0;
  bool ok = false;
};

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

enum class Pattern {
  /// The paper's pattern, repeated: Repeat(trials, ForceSuccess(Parallel(1, 1)[skill, monitor])). The
  /// skill (Localize on executor "skills") runs until shut down; the monitor (TimerMonitor on executor
  /// "monitors", another process) fails `period_ms` after its START. Measured: the monitor's FAILURE →
  /// the skill's SHUTDOWN taken by the skill's executor.
  kMonitorFailure,
  /// A sequence, repeated: Repeat(trials / 2, Sequence[Localize, Localize]) on executor "skills", each
  /// Localize succeeding `period_ms` after its START; "monitors" runs too (idle), as in the other pattern.
  /// Measured: a leaf's SUCCESS → the next leaf's START taken by the skill's executor.
  kSuccessNext,
};

/// Three processes take part — the controller and two scripted executors — and this one submits the
/// recipe and waits for its end.
Reaction measure_reaction(Pattern pattern, const std::string& journal_sync, int trials, int period_ms) {
  Reaction out;
  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  const std::string tag = std::string(pattern == Pattern::kMonitorFailure ? "failure-" : "success-") + journal_sync;
  const std::string trace_path = dir + "/stages-" + tag + ".tsv";
  const std::string receipt_path = dir + "/receipts-" + tag + ".tsv";
  cell.start("tc", "task_controller",
             {"--id", "tc", "--log-level", "warn", "--config",
              write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal-" + tag + ".sqlite"},
                                                {"journal_sync", journal_sync},
                                                {"stage_trace_path", trace_path}}
                                               .dump())});
  const json skill_behaviour = pattern == Pattern::kMonitorFailure
                                   ? json{{"mode", "run"}}
                                   : json{{"mode", "succeed"}, {"delay_s", period_ms / 1000.0}};
  cell.start("skills", "scripted_executor",
             {"--id", "skills", "--log-level", "warn", "--config",
              write_file(dir + "/skills.json", json{{"skills", {"Localize"}},
                                                    {"default", skill_behaviour},
                                                    {"receipt_trace_path", receipt_path}}
                                                   .dump())});
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
  bool done = false;
  int final_state = -1;
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) == "reaction" && terminal(s.state)) {
        done = true;
        final_state = s.state;
      }
    });
  });
  const json localize = {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}};
  json root;
  if (pattern == Pattern::kMonitorFailure) {
    const json parallel = {
        {"type", "Parallel"},
        {"success_threshold", 1},
        {"failure_threshold", 1},
        {"children",
         {localize, {{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 3600}}}}}}};
    root = {{"type", "Repeat"}, {"repetitions", trials}, {"child", {{"type", "ForceSuccess"}, {"child", parallel}}}};
  } else {
    root = {{"type", "Repeat"},
            {"repetitions", std::max(1, trials / 2)},
            {"child", {{"type", "Sequence"}, {"children", {localize, localize}}}}};
  }
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
  // The controller and the skill executor write their traces when they stop (stop_all waits for them).
  cell.stop_all();
  // Trials run one after the other, so the i-th cause and the i-th command belong to trial i: the
  // monitor's i-th FAILURE and the skill executor's i-th SHUTDOWN; or the i-th SUCCESS and the (i+1)-th
  // START (the first START has no cause).
  std::vector<tc::StageRecord> causes;
  std::vector<std::int64_t> stopped_ns;
  for (auto& r : tc::StageTrace::read(trace_path)) {
    if (pattern == Pattern::kMonitorFailure && r.executor_id == "monitors" && r.kind == "FAILURE")
      causes.push_back(std::move(r));
    else if (pattern == Pattern::kSuccessNext && r.executor_id == "skills" && r.kind == "SUCCESS")
      causes.push_back(std::move(r));
    else if (r.executor_id == "skills" && r.kind == "STOPPED")
      stopped_ns.push_back(r.stamp_wall_ns);
  }
  const int command_kind = pattern == Pattern::kMonitorFailure ? rigger_skill_SKILL_SHUTDOWN : rigger_skill_SKILL_START;
  std::vector<Receipt> commands;
  for (auto& r : read_receipts(receipt_path))
    if (r.executor_id == "skills" && r.task_id == "reaction" && r.kind == command_kind) commands.push_back(std::move(r));
  if (pattern == Pattern::kSuccessNext && !commands.empty()) commands.erase(commands.begin());
  const std::size_t n = std::min(causes.size(), commands.size());
  if (n == 0 || causes.size() < static_cast<std::size_t>(trials) - 1 || commands.size() + 1 < causes.size()) {
    std::fprintf(stderr, "unpaired: %zu causes, %zu commands (%s, %s)\n", causes.size(), commands.size(),
                 trace_path.c_str(), receipt_path.c_str());
    return out;
  }
  const auto us = [](std::int64_t from, std::int64_t to) { return static_cast<double>(to - from) / 1000.0; };
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = causes[i];
    const auto& r = commands[i];
    if (r.stamp_wall_ns < c.stamp_wall_ns) {
      std::fprintf(stderr, "trial %zu: the command is stamped before its cause\n", i);
      return out;
    }
    out.command_written_us.push_back(us(c.stamp_wall_ns, r.stamp_wall_ns));
    out.command_received_us.push_back(us(c.stamp_wall_ns, r.woke_wall_ns));
    out.command_to_seen_us.push_back(us(r.stamp_wall_ns, r.woke_wall_ns));
    if (pattern == Pattern::kMonitorFailure && i < stopped_ns.size())
      out.stopped_written_us.push_back(us(c.stamp_wall_ns, stopped_ns[i]));
    if (c.command_ns == 0 || c.flushed_ns == 0) continue;
    out.to_woke_us.push_back(us(c.stamp_wall_ns, c.woke_wall_ns));
    out.to_writing_us.push_back(us(c.woke_ns, c.writing_ns));
    out.writing_us.push_back(us(c.writing_ns, c.command_ns));
    out.to_engine_us.push_back(us(c.command_ns, c.engine_ns));
    out.to_flushed_us.push_back(us(c.engine_ns, c.flushed_ns));
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
  dds::Reader<rigger_skill_SkillCommand> commands(cell.participant(), rigger::protocol::skill::kCommand,
                                                  dds::qos::all_commands());
  cell.loop().on_data(commands, [&] {
    commands.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
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

  const Reaction failure = measure_reaction(Pattern::kMonitorFailure, "normal", trials, period_ms);
  const Reaction success = measure_reaction(Pattern::kSuccessNext, "normal", trials, period_ms);
  const Reaction full = measure_reaction(Pattern::kMonitorFailure, "full", std::max(1, trials / 5), period_ms);
  if (!failure.ok || !success.ok || !full.ok) return 1;
  // ddsperf at the rate the trials ran (rounded), on the same payload order (a SkillEvent is ~150 B).
  const int rate_hz = std::max(1, static_cast<int>(failure.trials_per_s + 0.5));
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
  std::printf("Reaction, %d trials each, received = the executor's event loop woke for the command:\n", trials);
  std::printf("%-62s %9s %9s %9s %7s\n", "", "p50 us", "p90 us", "p99 us", "n");
  std::printf("A. monitor FAILURE -> sibling SHUTDOWN, Repeat(ForceSuccess(Parallel(1,1)[skill, monitor])), %.0f per s\n",
              failure.trials_per_s);
  print_row("SHUTDOWN received (2 hops + controller), journal normal", failure.command_received_us);
  print_row("  SHUTDOWN written by the controller (1 hop + handling)", failure.command_written_us);
  print_row("  STOPPED written by the skill executor", failure.stopped_written_us);
  print_row("SHUTDOWN received, journal_sync full", full.command_received_us);
  std::printf("B. leaf SUCCESS -> next leaf's START, Repeat(Sequence[skill, skill]), %.0f per s\n", success.trials_per_s);
  print_row("START received (2 hops + controller), journal normal", success.command_received_us);
  print_row("  START written by the controller (1 hop + handling)", success.command_written_us);
  const auto stages = [](const char* label, const Reaction& r, const char* command) {
    std::printf("Per stage, %s (controller's stage trace, %zu trials):\n", label, r.to_woke_us.size());
    const std::string c = command;
    print_row("  1 event written -> controller woke (DDS, 1 hop)", r.to_woke_us);
    print_row(("  2 woke -> " + c + " handed to DDS (take, engine)").c_str(), r.to_writing_us);
    print_row(("  3 " + c + " write call (dds_write returns)").c_str(), r.writing_us);
    print_row(("  4 " + c + " written -> engine done").c_str(), r.to_engine_us);
    print_row("  5 engine done -> journal rows + node status flushed", r.to_flushed_us);
    print_row(("  6 " + c + " stamped -> executor woke (DDS, 1 hop)").c_str(), r.command_to_seen_us);
  };
  stages("A, journal normal", failure, "SHUTDOWN");
  stages("A, journal sync full", full, "SHUTDOWN");
  stages("B, journal normal", success, "START");
  const auto ref_row = [](const char* label, const rigger::bench::DdsperfLatency& r) {
    std::printf("%-62s %9.1f %9.1f %9.1f %7llu\n", label, r.p50_us / 2, r.p90_us / 2, r.p99_us / 2,
                static_cast<unsigned long long>(r.count));
  };
  std::printf("ddsperf one-way (half the round trip), 128 B, %d Hz:\n", rate_hz);
  ref_row("  ddsperf waitset triggering (as rigger's event loop)", waitset);
  ref_row("  ddsperf listener triggering (ddsperf's default)", listener);
  const auto ratios = [&](const char* label, const Reaction& r) {
    const double p50 = percentile(r.command_received_us, 0.5), p99 = percentile(r.command_received_us, 0.99);
    std::printf("%s / ddsperf waitset one-way: p50 %.2fx, p99 %.2fx (target <= 2x each); listener: p50 %.2fx\n", label,
                p50 / (waitset.p50_us / 2), p99 / (waitset.p99_us / 2), p50 / (listener.p50_us / 2));
  };
  ratios("A", failure);
  ratios("B", success);
  return measure_idle(idle_seconds);
}
