// The task controller as a real process (with a scripted executor) on a private domain; run on
// demand, not a test. Prints:
//
//  1. Reaction latency: a skill's SUCCESS event → the controller's START of the next node of a
//     Sequence of Localize skills, p50/p90/p99, measured two ways:
//       - receipt:  this process sees the SUCCESS (from the executor) and the START (from the
//                   controller); the gap is the controller's handling plus one DDS hop;
//       - stamps:   SkillCommand.stamp − SkillEvent.stamp (wall clocks of one host): the executor's
//                   publish → the controller's publish, one DDS hop plus the handling;
//     next to ddsperf ping/pong round trips measured in the same run (two hops, no handling).
//     Run twice: the journal on disk (SQLite, synchronous=FULL) and on /dev/shm (tmpfs), which shows
//     what the journal's fsyncs cost.
//  2. Idle CPU: CPU seconds per wall second (/proc/PID/stat utime+stime) of the controller with no
//     task, with 1 running leaf and with 100 running leaves (1 skill + 99 monitors in a Parallel),
//     each over --idle-seconds, next to an idle echo service measured over the same windows.
//
//   build-x/bench/task_controller_live_bench [--steps 300] [--idle-seconds 10] [--ddsperf-seconds 5]
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/executor/executor_endpoint.hpp"
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

/// utime + stime of `pid` in seconds, or a negative value when /proc cannot be read.
double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto paren = text.rfind(')');  // the command name may hold spaces
  if (paren == std::string::npos) return -1;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  unsigned long utime = 0, stime = 0;
  // After ")": state is field 3; utime and stime are fields 14 and 15.
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoul(field);
    if (i == 15) stime = std::stoul(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double us(Clock::duration d) {
  return std::chrono::duration<double, std::micro>(d).count();
}

std::int64_t wire_ns(const rigger_geometry_Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000000LL + t.nanosec;
}

struct Observer {
  explicit Observer(rigger::testing::Cell& cell)
      : recipes(cell.participant(), tc::kRecipeTopic, dds::qos::commands()),
        task_commands(cell.participant(), tc::kTaskCommandTopic, dds::qos::commands()),
        statuses(cell.participant(), tc::kTaskStatusTopic, dds::qos::state()),
        commands(cell.participant(), rigger::executor::kCommandTopic, dds::qos::commands()),
        events(cell.participant(), rigger::executor::kEventTopic, dds::qos::events()) {}

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

struct Timing {
  Clock::time_point seen;
  std::int64_t stamp_ns = 0;
};

struct Reaction {
  std::vector<double> receipt_us, stamp_us;
  bool ok = false;
};

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

/// Runs a Sequence of `steps` Localize skills (each succeeds at once) through a fresh controller whose
/// journal is `journal_path`, and collects SUCCESS(root/i) → START(root/i+1).
Reaction measure_reaction(const std::string& journal_path, int steps) {
  Reaction out;
  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  cell.start("tc", "task_controller",
             {"--id", "tc", "--log-level", "warn", "--config",
              write_file(dir + "/tc.json", json{{"journal_path", journal_path}}.dump())});
  cell.start(
      "exec", "scripted_executor",
      {"--id", "exec", "--log-level", "warn", "--config",
       write_file(dir + "/exec.json",
                  json{{"skills", {"Localize"}}, {"default", {{"mode", "succeed"}, {"delay_s", 0.002}}}}.dump())});
  if (!cell.wait_ready({"tc", "exec"}, 30s)) {
    std::fprintf(stderr, "services did not become ready\n%s", cell.logs().c_str());
    return out;
  }
  Observer obs(cell);
  if (!obs.recipes.wait_for_readers(1, 10s)) return out;
  std::map<std::string, Timing> success, start;
  bool done = false;
  int final_state = -1;
  cell.loop().on_data(obs.events, [&] {
    const auto now = Clock::now();
    obs.events.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
      if (e.kind == rigger_skill_SKILL_EVENT_SUCCESS) success[dds::to_string(e.node_id)] = {now, wire_ns(e.stamp)};
    });
  });
  cell.loop().on_data(obs.commands, [&] {
    const auto now = Clock::now();
    obs.commands.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
      if (c.kind == rigger_skill_SKILL_START) start[dds::to_string(c.node_id)] = {now, wire_ns(c.stamp)};
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
  json children = json::array();
  for (int i = 0; i < steps; ++i)
    children.push_back({{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}});
  obs.submit(
      "reaction",
      {{"recipe_version", 1}, {"task_id", "reaction"}, {"root", {{"type", "Sequence"}, {"children", children}}}});
  if (!cell.wait_until([&] { return done; }, std::chrono::seconds(30 + steps / 5))) {
    std::fprintf(stderr, "the reaction recipe did not finish\n");
    return out;
  }
  if (final_state != rigger_task_TASK_SUCCEEDED) {
    std::fprintf(stderr, "the reaction recipe ended in state %d\n%s", final_state, cell.logs().c_str());
    return out;
  }
  for (int i = 0; i + 1 < steps; ++i) {
    auto s = success.find("root/" + std::to_string(i));
    auto n = start.find("root/" + std::to_string(i + 1));
    if (s == success.end() || n == start.end()) continue;
    out.receipt_us.push_back(us(n->second.seen - s->second.seen));
    out.stamp_us.push_back(static_cast<double>(n->second.stamp_ns - s->second.stamp_ns) / 1000.0);
  }
  cell.stop_all();
  out.ok = !out.receipt_us.empty();
  return out;
}

void print_row(const char* label, const std::vector<double>& v) {
  using rigger::bench::percentile;
  std::printf("%-58s %9.1f %9.1f %9.1f %7zu\n", label, percentile(v, 0.5), percentile(v, 0.9), percentile(v, 0.99),
              v.size());
}

/// CPU seconds per wall second of each pid over `seconds` (the loop runs meanwhile, handling nothing).
std::vector<double> cpu_share(rigger::testing::Cell& cell, const std::vector<pid_t>& pids, int seconds) {
  std::vector<double> before;
  for (pid_t p : pids) before.push_back(cpu_seconds(p));
  const auto t0 = Clock::now();
  bool over = false;
  const auto timer = cell.loop().after(std::chrono::seconds(seconds), [&] { over = true; });
  cell.wait_until([&] { return over; }, std::chrono::seconds(seconds + 5));
  cell.loop().cancel(timer);
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  std::vector<double> share;
  for (std::size_t i = 0; i < pids.size(); ++i) share.push_back((cpu_seconds(pids[i]) - before[i]) / wall);
  return share;
}

int measure_idle(int seconds) {
  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  auto& tcp = cell.start("tc", "task_controller",
                         {"--id", "tc", "--log-level", "warn", "--config",
                          write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal.sqlite"}}.dump())});
  auto& exec =
      cell.start("exec", "scripted_executor",
                 {"--id", "exec", "--log-level", "warn", "--config",
                  write_file(dir + "/exec.json",
                             json{{"skills", {"Localize", "TimerMonitor"}}, {"default", {{"mode", "run"}}}}.dump())});
  auto& echo = cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
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
  const std::vector<pid_t> pids = {tcp.pid(), echo.pid(), exec.pid()};
  std::printf("\nIdle CPU (CPU s per wall s, /proc/PID/stat utime+stime over %d s each)\n", seconds);
  std::printf("%-34s %14s %14s %14s\n", "", "task_controller", "echo (idle)", "scripted exec");
  auto row = [&](const char* label, const std::vector<double>& s) {
    std::printf("%-34s %14.4f %14.4f %14.4f\n", label, s[0], s[1], s[2]);
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
  cell.stop_all();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  const int steps = int_option(argc, argv, "--steps", 300);
  const int idle_seconds = int_option(argc, argv, "--idle-seconds", 10);
  const int ddsperf_seconds = int_option(argc, argv, "--ddsperf-seconds", 5);

  const std::string disk_journal = "/tmp/rigger-bench-journal-" + std::to_string(::getpid()) + ".sqlite";
  const std::string shm_journal = "/dev/shm/rigger-bench-journal-" + std::to_string(::getpid()) + ".sqlite";
  const Reaction disk = measure_reaction(disk_journal, steps);
  const Reaction shm = measure_reaction(shm_journal, steps);
  for (const auto& f : {disk_journal, shm_journal})
    for (const char* suffix : {"", "-wal", "-shm"}) std::remove((f + suffix).c_str());
  if (!disk.ok || !shm.ok) return 1;

  std::uint32_t domain = 0;
  rigger::bench::DdsperfLatency ref;
  {
    rigger::testing::DomainLease lease;
    domain = lease.id();
    ref = rigger::bench::run_ddsperf_pingpong(domain, 1000, 64, ddsperf_seconds, true);
  }
  std::printf("Reaction: SUCCESS of root/i -> START of root/i+1, Sequence of %d Localize (scripted, 2 ms each)\n",
              steps);
  std::printf("%-58s %9s %9s %9s %7s\n", "", "p50 us", "p90 us", "p99 us", "n");
  print_row("journal on disk: receipt (handling + 1 hop)", disk.receipt_us);
  print_row("journal on disk: stamps (1 hop + handling)", disk.stamp_us);
  print_row("journal on /dev/shm: receipt", shm.receipt_us);
  print_row("journal on /dev/shm: stamps", shm.stamp_us);
  if (ref.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n", ref.raw.c_str());
  } else {
    std::printf("%-58s %9.1f %9.1f %9.1f %7llu\n", "ddsperf ping/pong round trip (2 hops, 64 B, 1 kHz, waitset)",
                ref.p50_us, ref.p90_us, ref.p99_us, static_cast<unsigned long long>(ref.count));
  }
  return measure_idle(idle_seconds);
}
