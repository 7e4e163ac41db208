// The task controller as a real process, with scripted executors, on a private domain; run on
// demand, not a test. Prints:
//
//  1. Reaction latency, across three processes (an executor → the controller → an
//     executor), p50/p90/p99:
//     A. a monitor's FAILURE written → the sibling skill's SHUTDOWN received by the skill's executor
//        (Repeat(ForceSuccess(Parallel(1, 1)[skill, monitor]))), with the journal as deployed
//        (journal_sync normal) and with journal_sync full;
//     B. a leaf's SUCCESS written → the next leaf's START received by its executor
//        (Repeat(Sequence[skill, skill])).
//     "Received" is the instant the executor's command handler began (scripted_executor's
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
//  3. The relay floor (relay_floor.cpp): after the controller, in the same cell, against the same executors
//     and receipt traces, a relay that reads the event and writes the command it causes and does
//     nothing else runs the same trials of A and B: p50 and p99 of rigger and of the relay, rigger / relay.
//  4. With --tail: the slowest 1 % of B's hand-overs, each with every dispatch of the controller's loop
//     near it (its stage trace's loop marks), and what overlapped the event's way in, counted.
//
//   build/bench/task_controller_live_bench [--trials 1000] [--period-ms 10] [--idle-seconds 60]
//                                          [--ddsperf-seconds 10] [--tail]
//
// Exit 0 when every run paired all its trials (each cause its command: none lost), the controller's and
// the relay's alike, and every task succeeded; the ratios are figures, not checks.
//
// The reaction's processes and measurement are in live_reaction.* (shared with test/bench's
// bench_network_matrix, which runs them across two lab hosts and with DDS Security).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "live_reaction.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using nlohmann::json;
namespace dds = rigger::dds;
using rigger::bench::measure_reaction;
using rigger::bench::Observer;
using rigger::bench::Pattern;
using rigger::bench::Reaction;
using rigger::bench::write_file;

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

double load_average() {
  double one_minute = -1;
  std::ifstream("/proc/loadavg") >> one_minute;
  return one_minute;
}

int measure_idle(int seconds, rigger::performance::Report& report) {
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
  if (!obs.recipes.wait_for_readers(1, 10s)) {
    std::fprintf(stderr, "this process's recipe writer did not match the controller's reader within 10 s\n");
    return 1;
  }
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
    rigger::bench::add_cpu_share(report, {"controller", "ddsperf pong", "echo", "scripted executor"}, 1, s, label);
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
  if (!cell.wait_until([&] { return state["one"] == rigger_task_TASK_CANCELED; }, 20s)) {
    // E.g. its executor stopped the skill on its own (CONTROLLER_LOST: the controller's liveliness lapsed
    // on a loaded machine): the task then ended FAILED before the cancel.
    std::fprintf(stderr, "task one did not end CANCELED (state %d)\n%s", state["one"], cell.logs().c_str());
    return 1;
  }

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
  return rigger::performance::save_for_main(report);
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  using rigger::bench::percentile;
  const int trials = int_option(argc, argv, "--trials", 1000);
  const int period_ms = std::max(1, int_option(argc, argv, "--period-ms", 10));
  const int idle_seconds = int_option(argc, argv, "--idle-seconds", 60);
  const int ddsperf_seconds = int_option(argc, argv, "--ddsperf-seconds", 10);
  const bool tail =
      std::find_if(argv + 1, argv + argc, [](const char* a) { return std::strcmp(a, "--tail") == 0; }) != argv + argc;

  // ddsperf at the rate the trials run (one per period plus the reaction, ~90 Hz at 10 ms), on the same
  // payload order (a SkillEvent is ~150 B). Half of its time before the reactions and half after, pooled:
  // on this VM ddsperf's one-way figure moved by half between two windows a minute apart, and the
  // reference should see the machine as the reactions did.
  const int rate_hz = std::max(1, static_cast<int>(1000.0 / (period_ms + 1) + 0.5));
  const int half = std::max(2, ddsperf_seconds / 2);
  rigger::bench::DdsperfLatency waitset, listener;
  rigger::testing::DomainLease lease;
  const auto pool = [](rigger::bench::DdsperfLatency& into, const rigger::bench::DdsperfLatency& r) {
    const double n = static_cast<double>(into.count), m = static_cast<double>(r.count);
    if (n + m == 0) return;
    into.p50_us = (into.p50_us * n + r.p50_us * m) / (n + m);
    into.p90_us = (into.p90_us * n + r.p90_us * m) / (n + m);
    into.p99_us = (into.p99_us * n + r.p99_us * m) / (n + m);
    into.count += r.count;
    into.raw += r.raw;
  };
  const auto reference = [&] {
    pool(waitset, rigger::bench::run_ddsperf_pingpong(lease.id(), rate_hz, 128, half, true));
    pool(listener, rigger::bench::run_ddsperf_pingpong(lease.id(), rate_hz, 128, half, false));
  };
  reference();
  const double load_before = load_average();
  rigger::bench::ReactionSetup with_relay;
  with_relay.relay = true;
  const Reaction failure = measure_reaction(Pattern::kMonitorFailure, "normal", trials, period_ms, with_relay);
  if (tail) with_relay.tail_fraction = 0.01;
  const Reaction success = measure_reaction(Pattern::kSuccessNext, "normal", trials, period_ms, with_relay);
  const Reaction full = measure_reaction(Pattern::kMonitorFailure, "full", std::max(1, trials / 5), period_ms);
  const double load_after = load_average();
  if (!failure.ok || !success.ok || !full.ok) return 1;
  // Every trial paired, the controller's and the relay's: A pairs each FAILURE, B each SUCCESS but the
  // last of the task, with the command it caused; a lost command leaves its trial unpaired.
  const std::size_t a_trials = static_cast<std::size_t>(trials), b_trials = 2 * std::max(1, trials / 2) - 1;
  if (failure.command_received_us.size() != a_trials || failure.relay.command_received_us.size() != a_trials ||
      success.command_received_us.size() != b_trials || success.relay.command_received_us.size() != b_trials) {
    std::fprintf(stderr, "trials paired: A %zu and relay %zu of %zu, B %zu and relay %zu of %zu\n",
                 failure.command_received_us.size(), failure.relay.command_received_us.size(), a_trials,
                 success.command_received_us.size(), success.relay.command_received_us.size(), b_trials);
    return 1;
  }
  reference();
  if (waitset.count == 0 || listener.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n%s\n", waitset.raw.c_str(), listener.raw.c_str());
    return 1;
  }
  std::printf("Reaction, %d trials each, received = the executor's command handler began:\n", trials);
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
  std::printf("ddsperf one-way (half the round trip), 128 B, %d Hz, %d s before the reactions and %d s after:\n",
              rate_hz, half, half);
  ref_row("  ddsperf waitset triggering (as rigger's event loop)", waitset);
  ref_row("  ddsperf listener triggering (ddsperf's default)", listener);
  std::printf("Commands for the skill's executor also taken by the monitors' executor: A %zu, B %zu, A full %zu\n",
              failure.misrouted, success.misrouted, full.misrouted);
  std::printf("STARTs sent again for want of an answer (journal START_SENT_AGAIN): A %zu, B %zu, A full %zu\n",
              failure.sent_again, success.sent_again, full.sent_again);
  const auto ratios = [&](const char* label, const Reaction& r) {
    const double p50 = percentile(r.command_received_us, 0.5), p99 = percentile(r.command_received_us, 0.99);
    std::printf("%s / ddsperf waitset one-way: p50 %.2fx, p99 %.2fx (target <= 2x each); listener: p50 %.2fx\n", label,
                p50 / (waitset.p50_us / 2), p99 / (waitset.p99_us / 2), p50 / (listener.p50_us / 2));
  };
  ratios("A", failure);
  ratios("B", success);
  std::printf(
      "\nRigger next to the relay floor (relay_floor.cpp: the same hop, nothing else; same executors,\n"
      "same receipt traces, right after the controller; load average %.2f before, %.2f after):\n",
      load_before, load_after);
  std::printf("%-44s %9s %9s %7s %9s %9s %7s\n", "", "rigger50", "relay50", "ratio", "rigger99", "relay99", "ratio");
  const auto versus = [](const char* label, const std::vector<double>& rigger, const std::vector<double>& relay) {
    const double r50 = percentile(rigger, 0.5), f50 = percentile(relay, 0.5);
    const double r99 = percentile(rigger, 0.99), f99 = percentile(relay, 0.99);
    std::printf("%-44s %9.1f %9.1f %6.2fx %9.1f %9.1f %6.2fx\n", label, r50, f50, r50 / std::max(1e-9, f50), r99, f99,
                r99 / std::max(1e-9, f99));
  };
  versus("A SHUTDOWN received (2 hops + handling)", failure.command_received_us, failure.relay.command_received_us);
  versus("A SHUTDOWN written (1 hop + handling)", failure.command_written_us, failure.relay.command_written_us);
  versus("A event written -> woke (1 hop)", failure.to_woke_us, failure.relay.to_woke_us);
  versus("B START received (2 hops + handling)", success.command_received_us, success.relay.command_received_us);
  versus("B START written (1 hop + handling)", success.command_written_us, success.relay.command_written_us);
  versus("B event written -> woke (1 hop)", success.to_woke_us, success.relay.to_woke_us);
  print_row("relay A: woke -> SHUTDOWN write returned", failure.relay.handling_us);
  print_row("relay B: woke -> START write returned", success.relay.handling_us);
  if (tail) std::printf("\nB, journal normal. %s", success.tail.c_str());

  rigger::performance::Report report(
      "task_controller_live_bench",
      "Skill-event reaction of the task controller across three processes, " + std::to_string(trials) +
          " trials each, next to ddsperf's one-way latency (128 B, " + std::to_string(rate_hz) +
          " Hz) and to a bare relay floor (the same hop, nothing else); idle CPU over " + std::to_string(idle_seconds) +
          " s per row next to an idle ddsperf pong");
  using rigger::bench::add_quantiles;
  using rigger::bench::quantiles;
  const auto floor = rigger::bench::one_way(waitset);
  const std::string one_way = "ddsperf waitset one way";
  add_quantiles(report, "A SHUTDOWN received, journal normal", quantiles(failure.command_received_us), "us", one_way,
                floor);
  add_quantiles(report, "A SHUTDOWN written", quantiles(failure.command_written_us), "us", one_way, floor);
  add_quantiles(report, "A STOPPED written", quantiles(failure.stopped_written_us), "us");
  add_quantiles(report, "A SHUTDOWN received, journal_sync full", quantiles(full.command_received_us), "us",
                "A SHUTDOWN received, journal normal", quantiles(failure.command_received_us));
  add_quantiles(report, "B START received, journal normal", quantiles(success.command_received_us), "us", one_way,
                floor);
  add_quantiles(report, "B START written", quantiles(success.command_written_us), "us", one_way, floor);
  add_quantiles(report, "ddsperf listener one way", rigger::bench::one_way(listener), "us", one_way, floor);
  add_quantiles(report, "A SHUTDOWN received, rigger", quantiles(failure.command_received_us), "us",
                "A SHUTDOWN received, relay floor", quantiles(failure.relay.command_received_us));
  add_quantiles(report, "A SHUTDOWN written, rigger", quantiles(failure.command_written_us), "us",
                "A SHUTDOWN written, relay floor", quantiles(failure.relay.command_written_us));
  add_quantiles(report, "B START received, rigger", quantiles(success.command_received_us), "us",
                "B START received, relay floor", quantiles(success.relay.command_received_us));
  add_quantiles(report, "B START written, rigger", quantiles(success.command_written_us), "us",
                "B START written, relay floor", quantiles(success.relay.command_written_us));
  report.add({"load average (1 min) before the reactions", load_before, "", "", 0});
  report.add({"load average (1 min) after the reactions", load_after, "", "", 0});
  report.add({"A trials per s", failure.trials_per_s, "1/s", "", 0});
  report.add({"B trials per s", success.trials_per_s, "1/s", "", 0});
  const auto stage_figures = [&](const std::string& label, const Reaction& r) {
    add_quantiles(report, label + " stage 1 event -> controller woke", quantiles(r.to_woke_us), "us");
    add_quantiles(report, label + " stage 2 woke -> command handed to DDS", quantiles(r.to_writing_us), "us");
    add_quantiles(report, label + " stage 3 command write call", quantiles(r.writing_us), "us");
    add_quantiles(report, label + " stage 4 command written -> engine done", quantiles(r.to_engine_us), "us");
    add_quantiles(report, label + " stage 5 engine done -> flushed", quantiles(r.to_flushed_us), "us");
    add_quantiles(report, label + " stage 6 command -> executor woke", quantiles(r.command_to_seen_us), "us");
  };
  stage_figures("A", failure);
  stage_figures("A full", full);
  stage_figures("B", success);
  const std::pair<const char*, const Reaction*> runs[] = {{"A", &failure}, {"B", &success}, {"A full", &full}};
  for (const auto& [label, r] : runs) {
    report.add({std::string("commands also taken by the monitors' executor, ") + label,
                static_cast<double>(r->misrouted), "commands", "", 0});
    report.add({std::string("STARTs sent again, ") + label, static_cast<double>(r->sent_again), "commands", "", 0});
  }
  return measure_idle(idle_seconds, report);
}
