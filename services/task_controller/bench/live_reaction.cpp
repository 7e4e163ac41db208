#include "live_reaction.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "journal.hpp"
#include "stage_trace.hpp"
#include "task_port.hpp"

namespace rigger::bench {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using nlohmann::json;
namespace tc = rigger::task_controller;
namespace dds = rigger::dds;

/// Nodes of a recipe tree (children, a decorator's child, a decision's options' children).
int count_nodes(const json& node) {
  int n = 1;
  if (node.contains("children"))
    for (const json& c : node["children"]) n += count_nodes(c);
  if (node.contains("child")) n += count_nodes(node["child"]);
  if (node.contains("options"))
    for (const json& o : node["options"]) n += count_nodes(o["child"]);
  return n;
}

/// VmHWM and VmRSS of `pid` from /proc/PID/status, KiB (0 when unreadable).
std::pair<long, long> memory_kib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  long peak = 0, rss = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmHWM:", 0) == 0) peak = std::stol(line.substr(6));
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stol(line.substr(6));
  }
  return {peak, rss};
}

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}


/// One run's causes (from a stage trace) and the commands they caused (from a receipt trace), in order.
/// Trials run one after the other, so the i-th cause and the i-th command belong to trial i: the
/// monitor's i-th FAILURE and the skill executor's i-th SHUTDOWN; or the i-th SUCCESS and the (i+1)-th
/// START (the first START has no cause).
struct Trials {
  std::vector<tc::StageRecord> causes;
  std::vector<Receipt> commands;
  std::vector<std::int64_t> stopped_ns;
  std::vector<tc::StageRecord> all;  ///< every record of the trace since the run began
};

Trials collect(Pattern pattern, const std::string& trace_path, std::int64_t since_wall_ns,
               const std::string& receipt_path, const std::string& task_id) {
  Trials t;
  for (auto& r : tc::StageTrace::read(trace_path)) {
    if (r.stamp_wall_ns < since_wall_ns) continue;
    t.all.push_back(r);
    if (pattern == Pattern::kMonitorFailure && r.executor_id == "monitors" && r.kind == "FAILURE")
      t.causes.push_back(std::move(r));
    else if (pattern == Pattern::kSuccessNext && r.executor_id == "skills" && r.kind == "SUCCESS")
      t.causes.push_back(std::move(r));
    else if (r.executor_id == "skills" && r.kind == "STOPPED")
      t.stopped_ns.push_back(r.stamp_wall_ns);
  }
  const int command_kind = pattern == Pattern::kMonitorFailure ? rigger_skill_SKILL_SHUTDOWN : rigger_skill_SKILL_START;
  for (auto& r : read_receipts(receipt_path)) {
    if (r.executor_id != "skills" || r.task_id != task_id || r.kind != command_kind) continue;
    // The same sample written again (the relay's first START, until its executor matched) is one command.
    if (!t.commands.empty() && t.commands.back().stamp_wall_ns == r.stamp_wall_ns &&
        t.commands.back().node_id == r.node_id)
      continue;
    t.commands.push_back(std::move(r));
  }
  if (pattern == Pattern::kSuccessNext && !t.commands.empty()) t.commands.erase(t.commands.begin());
  return t;
}

/// Pattern A pairs every FAILURE with a SHUTDOWN; pattern B's last SUCCESS ends the task (no next START).
/// Returns the number of trials, 0 (and why on stderr) when they do not pair.
std::size_t paired_trials(Pattern pattern, const Trials& t, const std::string& what) {
  const std::size_t n =
      pattern == Pattern::kMonitorFailure ? t.causes.size() : std::min(t.causes.size(), t.commands.size());
  const bool paired = n > 0 && t.commands.size() == n &&
                      (pattern == Pattern::kMonitorFailure || t.causes.size() == n || t.causes.size() == n + 1);
  if (!paired)
    std::fprintf(stderr, "%s: unpaired: %zu causes, %zu commands\n", what.c_str(), t.causes.size(), t.commands.size());
  for (std::size_t i = 0; paired && i < n; ++i)
    if (t.commands[i].stamp_wall_ns < t.causes[i].stamp_wall_ns) {
      std::fprintf(stderr, "%s: trial %zu: the command is stamped before its cause\n", what.c_str(), i);
      return 0;
    }
  return paired ? n : 0;
}

/// What the controller's loop did while trial `c`'s event was on its way in (from its stamp to the
/// handler's wake-up): the handlers that ran then, and whether the listener or the loop thread (pending:
/// the loop was busy when it came) ran the event handler.
struct WayIn {
  std::set<std::string> overlapped;
  std::string path;
};

WayIn way_in(const tc::StageRecord& c, const std::vector<tc::LoopMark>& marks) {
  WayIn w;
  const std::int64_t stamp = c.stamp_wall_ns - (c.woke_wall_ns - c.woke_ns);  // on the steady clock
  const auto end = std::upper_bound(marks.begin(), marks.end(), c.woke_ns,
                                    [](std::int64_t ns, const tc::LoopMark& m) { return ns < m.ns; });
  // Handlers last a few ms at most: look 50 ms back for those still running at the stamp.
  auto it = std::lower_bound(marks.begin(), end, stamp - 50000000,
                             [](const tc::LoopMark& m, std::int64_t ns) { return m.ns < ns; });
  std::map<std::string, std::int64_t> open;  // label → began
  for (; it != end; ++it) {
    if (it->phase == 'b') open[it->what] = it->ns;
    if (it->phase == 'b' && (it->what == "listener events" || it->what == "pending events")) w.path = it->what;
    if (it->phase != 'e' || !open.count(it->what)) continue;
    if (it->ns > stamp && it->what != "listener events" && it->what != "pending events") w.overlapped.insert(it->what);
    open.erase(it->what);
  }
  for (const auto& [what, began] : open)
    if (what != "listener events" && what != "pending events") w.overlapped.insert(what + " (still running)");
  return w;
}

std::string tail_report(const Trials& t, std::size_t n, const std::vector<tc::LoopMark>& marks, double fraction) {
  std::ostringstream out;
  if (marks.empty()) return "no loop marks (" + std::to_string(n) + " trials): the controller wrote none\n";
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  const auto received = [&](std::size_t i) { return t.commands[i].woke_wall_ns - t.causes[i].stamp_wall_ns; };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return received(a) > received(b); });
  const std::size_t k = std::min(n, std::max<std::size_t>(1, static_cast<std::size_t>(n * fraction + 0.999)));
  // Counted over the tail and over every trial: what overlapped the way in, which thread ran the handler.
  std::map<std::string, std::pair<int, int>> counts;  // what → (in the tail, in all)
  for (std::size_t rank = 0; rank < n; ++rank) {
    const auto& c = t.causes[order[rank]];
    if (c.woke_ns == 0) continue;
    const WayIn w = way_in(c, marks);
    for (std::string what : w.overlapped) {
      what = "overlapped by " + what;
      (rank < k ? counts[what].first : counts[what].second)++;
    }
    const std::string path = "handler run by " + (w.path.empty() ? std::string("?") : w.path);
    (rank < k ? counts[path].first : counts[path].second)++;
  }
  out << "Tail: the " << k << " slowest of " << n << " trials (event written -> command received), each with every\n"
      << "dispatch of the controller's loop from 2 ms before the event to 0.5 ms after the command arrived\n"
      << "(us from the event's stamp; b/e: a handler began/ended):\n";
  const auto line = [&](std::int64_t ns, std::int64_t zero, const std::string& what) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "  %+10.1f  ", static_cast<double>(ns - zero) / 1000.0);
    return std::make_pair(ns, buf + what);
  };
  for (std::size_t rank = 0; rank < k; ++rank) {
    const std::size_t i = order[rank];
    const auto& c = t.causes[i];
    const auto& r = t.commands[i];
    if (c.woke_ns == 0) continue;
    const std::int64_t offset = c.woke_wall_ns - c.woke_ns;  // wall - steady, this process's
    const std::int64_t stamp = c.stamp_wall_ns - offset, arrived = r.woke_wall_ns - offset;
    std::vector<std::pair<std::int64_t, std::string>> lines;
    lines.push_back(line(stamp, stamp, c.executor_id + " wrote " + c.kind));
    lines.push_back(line(c.woke_ns, stamp, "controller's handler woke"));
    if (c.writing_ns) lines.push_back(line(c.writing_ns, stamp, "command handed to DDS"));
    if (c.command_ns) lines.push_back(line(c.command_ns, stamp, "command write returned"));
    if (c.engine_ns) lines.push_back(line(c.engine_ns, stamp, "engine done"));
    if (c.flushed_ns) lines.push_back(line(c.flushed_ns, stamp, "its journal rows + node statuses flushed"));
    lines.push_back(line(r.stamp_wall_ns - offset, stamp, "command stamped"));
    lines.push_back(line(arrived, stamp, "executor's command handler began"));
    const std::int64_t from = stamp - 2000000, to = arrived + 500000;
    for (const auto& o : t.all)
      if (o.woke_ns >= from && o.woke_ns <= to && o.stamp_wall_ns != c.stamp_wall_ns)
        lines.push_back(line(o.woke_ns, stamp, "  (handled " + o.executor_id + " " + o.kind + ")"));
    for (const auto& m : marks)
      if (m.ns >= from && m.ns <= to)
        lines.push_back(line(m.ns, stamp, "    loop " + m.what + (m.phase == '.' ? "" : std::string(" ") + m.phase)));
    std::stable_sort(lines.begin(), lines.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    out << "trial " << i << ": " << static_cast<double>(received(i)) / 1000.0 << " us\n";
    for (const auto& l : lines) out << l.second << "\n";
  }
  out << "On the way in (event written -> handler woke), trials of the tail / of the rest:\n";
  for (const auto& [what, c] : counts) out << "  " << what << ": " << c.first << " / " << c.second << "\n";
  return out.str();
}

}  // namespace

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

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

Observer::Observer(rigger::testing::Cell& cell)
    : recipes(cell.participant(), rigger::protocol::task::kRecipe),
      task_commands(cell.participant(), rigger::protocol::task::kCommand),
      statuses(cell.participant(), rigger::protocol::task::kStatus) {}

void Observer::submit(const std::string& task_id, const json& recipe) {
  rigger_task_Recipe r{};
  const std::string text = recipe.dump(), submitter = "bench";
  r.task_id = dds::wire_string(task_id);
  r.recipe_json = dds::wire_string(text);
  r.submitter = dds::wire_string(submitter);
  r.stamp = dds::wire_now();
  recipes.write(r);
}

void Observer::cancel(const std::string& task_id) {
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

Reaction measure_reaction(Pattern pattern, const std::string& journal_sync, int trials, int period_ms,
                          const ReactionSetup& setup) {
  Reaction out;
  rigger::testing::Cell cell(setup.cell_subfolder);
  const auto start = [&](const std::string& name, const std::string& binary, std::vector<std::string> args) {
    if (setup.start)
      setup.start(cell, name, binary, std::move(args));
    else
      cell.start(name, binary, std::move(args));
  };
  const std::string dir = cell.log_dir();
  const std::string tag = std::string(pattern == Pattern::kMonitorFailure ? "failure-" : "success-") + journal_sync;
  const std::string trace_path = dir + "/stages-" + tag + ".tsv";
  const std::string receipt_path = dir + "/receipts-" + tag + ".tsv";
  const std::string monitor_receipt_path = dir + "/monitor-receipts-" + tag + ".tsv";
  start("tc", "task_controller",
        {"--id", "tc", "--log-level", "warn", "--config",
         write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal-" + tag + ".sqlite"},
                                           {"journal_sync", journal_sync},
                                           {"stage_trace_path", trace_path},
                                           {"max_recipe_bytes", 64U * 1024U * 1024U},
                                           {"max_recipe_nodes", std::max(50000, 2 * setup.tree_nodes)}}
                                          .dump())});
  const json skill_behaviour = pattern == Pattern::kMonitorFailure
                                   ? json{{"mode", "run"}}
                                   : json{{"mode", "succeed"}, {"delay_s", period_ms / 1000.0}};
  start("skills", "scripted_executor",
        {"--id", "skills", "--log-level", "warn", "--config",
         write_file(dir + "/skills.json", json{{"skills", {"Localize", "Pick"}},
                                               {"default", skill_behaviour},
                                               {"receipt_trace_path", receipt_path}}
                                              .dump())});
  start("monitors", "scripted_executor",
        {"--id", "monitors", "--log-level", "warn", "--config",
         write_file(dir + "/monitors.json",
                    json{{"skills", {"TimerMonitor"}},
                         {"receipt_trace_path", monitor_receipt_path},
                         {"behaviours",
                          {{"TimerMonitor", {{"mode", "fail"}, {"delay_s", period_ms / 1000.0}, {"code", "BENCH"}}}}}}
                        .dump())});
  if (!cell.wait_ready({"tc", "skills", "monitors"}, 30s)) {
    std::fprintf(stderr, "services did not become ready\n%s", cell.logs().c_str());
    return out;
  }
  Observer obs(cell);
  // This process's endpoints matched the controller's before the first trial: with DDS Security an
  // endpoint matches only after its participant's handshake and token exchange, later than READY.
  if (!obs.recipes.wait_for_readers(1, 10s) || !obs.statuses.wait_for_writers(1, 10s)) {
    std::fprintf(stderr, "this process's task endpoints did not match the controller's within 10 s\n%s",
                 cell.logs().c_str());
    return out;
  }
  std::map<std::string, int> final_state;  // of each task that ended
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (terminal(s.state)) final_state[dds::to_string(s.task_id)] = s.state;
    });
  });
  const json localize = {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}};
  const auto recipe = [&](const std::string& task_id, int repetitions) {
    json root;
    if (pattern == Pattern::kMonitorFailure) {
      const json parallel = {
          {"type", "Parallel"},
          {"success_threshold", 1},
          {"failure_threshold", 1},
          {"children",
           {localize, {{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 3600}}}}}}};
      root = {{"type", "Repeat"}, {"repetitions", repetitions}, {"child", {{"type", "ForceSuccess"}, {"child", parallel}}}};
    } else {
      // Pick, not Localize: a localization's SUCCESS also has the controller ask the world model for the
      // pose (for a resume), which this cell has no world model to answer.
      const json pick = {{"type", "Skill"}, {"skill", "Pick"}, {"params", {{"object", "load"}, {"grasp", "load/grasp_top"}}}};
      root = {{"type", "Repeat"},
              {"repetitions", std::max(1, repetitions / 2)},
              {"child", {{"type", "Sequence"}, {"children", {pick, pick}}}}};
    }
    out.tree_nodes = count_nodes(root);
    if (setup.tree_nodes > out.tree_nodes + 2) {
      // Leaves that never start, after the pattern's tree in a Fallback: the tree is as large as asked,
      // the trials as they were.
      const json idle = {{"type", "Skill"}, {"skill", "Pick"}, {"params", {{"object", "load"}, {"grasp", "load/grasp_top"}}}};
      // Sequences of at most 1000 leaves (a node may have 10000 children).
      json rest = {{"type", "Sequence"}, {"children", json::array()}};
      for (int i = out.tree_nodes + 2; i < setup.tree_nodes;) {
        json part = {{"type", "Sequence"}, {"children", json::array()}};
        ++i;
        for (int k = 0; k < 1000 && i < setup.tree_nodes; ++k, ++i) part["children"].push_back(idle);
        rest["children"].push_back(std::move(part));
      }
      root = {{"type", "Fallback"}, {"children", {root, rest}}};
      out.tree_nodes = count_nodes(root);
    }
    json r = {{"recipe_version", 1}, {"task_id", task_id}, {"root", root}};
    // Pick's precondition (B's leaves and the idle ones of a large tree).
    if (pattern == Pattern::kSuccessNext || setup.tree_nodes > 0) r["assumptions"] = {"localized(load)"};
    return r;
  };
  // Runs task `task_id` to its end; false (and why on stderr) unless it SUCCEEDED.
  const auto run = [&](const std::string& task_id, int repetitions) {
    obs.submit(task_id, recipe(task_id, repetitions));
    if (!cell.wait_until([&] { return final_state.count(task_id) > 0; },
                         std::chrono::milliseconds(30000 + repetitions * (period_ms + 20)))) {
      std::fprintf(stderr, "the %s recipe did not finish\n", task_id.c_str());
      return false;
    }
    if (final_state[task_id] != rigger_task_TASK_SUCCEEDED) {
      std::fprintf(stderr, "the %s recipe ended in state %d\n%s", task_id.c_str(), final_state[task_id],
                   cell.logs().c_str());
      return false;
    }
    return true;
  };
  if (setup.warmup_trials > 0 && !run("warmup", setup.warmup_trials)) return out;
  // The stage trace names no task: the trials' events are those stamped after the submission.
  const std::int64_t submitted_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count();
  const auto t0 = Clock::now();
  if (!run("reaction", trials)) return out;
  out.trials_per_s = trials / std::chrono::duration<double>(Clock::now() - t0).count();
  const std::string relay_trace = dir + "/relay-" + tag + ".tsv";
  std::tie(out.controller_peak_kib, out.controller_rss_kib) = memory_kib(cell.process("tc").pid());
  if (setup.relay) {
    // The controller writes its stage trace as it stops; the relay then has the executors to itself.
    const auto tc_status = cell.stop("tc", SIGINT, 10s);
    if (!tc_status || !tc_status->ok()) {
      std::fprintf(stderr, "the controller did not stop cleanly\n%s", cell.logs().c_str());
      return out;
    }
    auto& relay = cell.start("relay", "task_controller_relay_floor",
                             {"--pattern", pattern == Pattern::kMonitorFailure ? "failure" : "success", "--trials",
                              std::to_string(trials), "--trace", relay_trace});
    // A command the relay lost stalls it (it writes nothing again once its executors answered).
    if (!cell.wait_until([&] { return !relay.running(); },
                         std::chrono::milliseconds(30000 + trials * (period_ms + 20)))) {
      std::fprintf(stderr, "the relay floor did not finish its trials (a lost command stalls it)\n%s",
                   cell.logs().c_str());
      return out;
    }
    const auto relay_status = relay.wait(1s);
    if (!relay_status || !relay_status->ok()) {
      std::fprintf(stderr, "the relay floor failed\n%s", cell.logs().c_str());
      return out;
    }
  }
  // The controller and the skill executor write their traces when they stop (stop_all waits for them).
  cell.stop_all();
  Trials t = collect(pattern, trace_path, submitted_ns, receipt_path, "reaction");
  // Commands go to their executor alone (the controller writes them in its partition once its reader
  // matched): the monitors' executor should have taken none of the skill's.
  for (const auto& r : read_receipts(monitor_receipt_path))
    if (r.executor_id == "skills" && (r.task_id == "reaction" || r.task_id == "relay")) ++out.misrouted;
  {
    const tc::Journal journal(dir + "/journal-" + tag + ".sqlite");
    for (const char* task : {"warmup", "reaction"})
      for (const auto& r : journal.timeline(task, 1000000))
        if (r.kind == "COMMAND" && r.code == tc::codes::kStartSentAgain) ++out.sent_again;
  }
  const std::size_t n = paired_trials(pattern, t, "controller");
  const bool stopped_paired = pattern != Pattern::kMonitorFailure || t.stopped_ns.size() == n;
  const bool stray_stopped =
      pattern == Pattern::kMonitorFailure && t.stopped_ns.size() > n && setup.allow_stray_stopped;
  if (n == 0 || (!stopped_paired && !stray_stopped)) {
    std::fprintf(stderr, "%zu causes, %zu commands, %zu STOPPED (%s, %s)\n", t.causes.size(), t.commands.size(),
                 t.stopped_ns.size(), trace_path.c_str(), receipt_path.c_str());
    return out;
  }
  if (stray_stopped) {
    out.stray_stopped = t.stopped_ns.size() - n;
    std::fprintf(stderr,
                 "%zu STOPPED for %zu SHUTDOWN: the skill's executor stopped the skill on its own (%s says why, e.g. "
                 "CONTROLLER_LOST); the STOPPED figures are left out\n",
                 t.stopped_ns.size(), n, cell.process("skills").log_path().c_str());
  }
  const auto us = [](std::int64_t from, std::int64_t to) { return static_cast<double>(to - from) / 1000.0; };
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = t.causes[i];
    const auto& r = t.commands[i];
    out.command_written_us.push_back(us(c.stamp_wall_ns, r.stamp_wall_ns));
    out.command_received_us.push_back(us(c.stamp_wall_ns, r.woke_wall_ns));
    out.command_to_seen_us.push_back(us(r.stamp_wall_ns, r.woke_wall_ns));
    if (pattern == Pattern::kMonitorFailure && stopped_paired)
      out.stopped_written_us.push_back(us(c.stamp_wall_ns, t.stopped_ns[i]));
    if (c.command_ns == 0 || c.flushed_ns == 0) continue;
    out.to_woke_us.push_back(us(c.stamp_wall_ns, c.woke_wall_ns));
    out.to_writing_us.push_back(us(c.woke_ns, c.writing_ns));
    out.writing_us.push_back(us(c.writing_ns, c.command_ns));
    out.to_engine_us.push_back(us(c.command_ns, c.engine_ns));
    out.to_flushed_us.push_back(us(c.engine_ns, c.flushed_ns));
  }
  if (out.to_woke_us.size() != n)
    std::fprintf(stderr, "stage trace: %zu of %zu trials traced (%s)\n", out.to_woke_us.size(), n, trace_path.c_str());
  if (setup.tail_fraction > 0)
    out.tail = tail_report(t, n, tc::StageTrace::read_marks(trace_path), setup.tail_fraction);
  if (setup.relay) {
    const Trials f = collect(pattern, relay_trace, 0, receipt_path, "relay");
    const std::size_t m = paired_trials(pattern, f, "relay floor");
    if (m == 0) return out;
    for (std::size_t i = 0; i < m; ++i) {
      const auto& c = f.causes[i];
      const auto& r = f.commands[i];
      out.relay.command_written_us.push_back(us(c.stamp_wall_ns, r.stamp_wall_ns));
      out.relay.command_received_us.push_back(us(c.stamp_wall_ns, r.woke_wall_ns));
      out.relay.to_woke_us.push_back(us(c.stamp_wall_ns, c.woke_wall_ns));
      out.relay.handling_us.push_back(us(c.woke_ns, c.command_ns));
    }
  }
  out.ok = true;
  return out;
}

}  // namespace rigger::bench
