#include "live_reaction.hpp"

#include <cstdio>
#include <fstream>
#include <map>
#include <utility>

#include "rigger/dds/conversions.hpp"
#include "stage_trace.hpp"

namespace rigger::bench {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using nlohmann::json;
namespace tc = rigger::task_controller;
namespace dds = rigger::dds;

std::int64_t wire_ns(const rigger_geometry_Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000000LL + t.nanosec;
}

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

}  // namespace

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

Observer::Observer(rigger::testing::Cell& cell)
    : recipes(cell.participant(), rigger::protocol::task::kRecipe),
      task_commands(cell.participant(), rigger::protocol::task::kCommand),
      statuses(cell.participant(), rigger::protocol::task::kStatus),
      commands(cell.participant(), rigger::protocol::skill::kCommand),
      events(cell.participant(), rigger::protocol::skill::kEvent) {}

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

Reaction measure_reaction(const std::string& journal_sync, int trials, int period_ms, const ReactionSetup& setup) {
  Reaction out;
  rigger::testing::Cell cell(setup.cell_subfolder);
  const auto start = [&](const std::string& name, const std::string& binary, std::vector<std::string> args) {
    if (setup.start)
      setup.start(cell, name, binary, std::move(args));
    else
      cell.start(name, binary, std::move(args));
  };
  const std::string dir = cell.log_dir();
  const std::string trace_path = dir + "/stages-" + journal_sync + ".tsv";
  start("tc", "task_controller",
        {"--id", "tc", "--log-level", "warn", "--config",
         write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal-" + journal_sync + ".sqlite"},
                                           {"journal_sync", journal_sync},
                                           {"stage_trace_path", trace_path}}
                                          .dump())});
  start("skills", "scripted_executor",
        {"--id", "skills", "--log-level", "warn", "--config",
         write_file(dir + "/skills.json", json{{"skills", {"Localize"}}, {"default", {{"mode", "run"}}}}.dump())});
  start("monitors", "scripted_executor",
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
  // Every endpoint of this process matched before the first trial: with DDS Security an endpoint
  // matches only after its participant's handshake and token exchange, later than READY, and a
  // FAILURE or SHUTDOWN written before would be missed here.
  if (!obs.recipes.wait_for_readers(1, 10s) || !obs.statuses.wait_for_writers(1, 10s) ||
      !obs.commands.wait_for_writers(1, 10s) || !obs.events.wait_for_writers(2, 10s)) {
    std::fprintf(stderr, "this process's task and skill endpoints did not match the services' within 10 s\n%s",
                 cell.logs().c_str());
    return out;
  }
  // Trials run one after the other (the next starts after the skill STOPPED), so the i-th FAILURE,
  // SHUTDOWN and STOPPED of task "reaction" belong to trial i.
  std::vector<std::int64_t> failure_ns, shutdown_stamp_ns, shutdown_seen_ns, stopped_ns;
  std::map<std::string, int> final_state;  // of each task that ended
  cell.loop().on_data(obs.events, [&] {
    obs.events.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
      if (dds::to_string(e.task_id) != "reaction") return;
      const std::string executor = dds::to_string(e.executor_id);
      if (executor == "monitors" && e.kind == rigger_skill_SKILL_EVENT_FAILURE) failure_ns.push_back(wire_ns(e.stamp));
      if (executor == "skills" && e.kind == rigger_skill_SKILL_EVENT_STOPPED) stopped_ns.push_back(wire_ns(e.stamp));
    });
  });
  cell.loop().on_data(obs.commands, [&] {
    const std::int64_t seen = wire_ns(dds::wire_now());
    obs.commands.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
      if (c.kind != rigger_skill_SKILL_SHUTDOWN || dds::to_string(c.executor_id) != "skills" ||
          dds::to_string(c.task_id) != "reaction")
        return;
      shutdown_stamp_ns.push_back(wire_ns(c.stamp));
      shutdown_seen_ns.push_back(seen);
    });
  });
  cell.loop().on_data(obs.statuses, [&] {
    obs.statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (terminal(s.state)) final_state[dds::to_string(s.task_id)] = s.state;
    });
  });
  const json parallel = {
      {"type", "Parallel"},
      {"success_threshold", 1},
      {"failure_threshold", 1},
      {"children",
       {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
        {{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 3600}}}}}}};
  const auto recipe = [&](const std::string& task_id, int repetitions) {
    const json root = {
        {"type", "Repeat"}, {"repetitions", repetitions}, {"child", {{"type", "ForceSuccess"}, {"child", parallel}}}};
    return json{{"recipe_version", 1}, {"task_id", task_id}, {"root", root}};
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
  const auto t0 = Clock::now();
  if (!run("reaction", trials)) return out;
  out.trials_per_s = trials / std::chrono::duration<double>(Clock::now() - t0).count();
  cell.stop_all();
  const std::size_t n = failure_ns.size();
  const bool stopped_paired = stopped_ns.size() == n;
  const bool stray_stopped = stopped_ns.size() > n && setup.allow_stray_stopped;
  if (n == 0 || shutdown_stamp_ns.size() != n || (!stopped_paired && !stray_stopped)) {
    std::fprintf(stderr, "unpaired events: %zu FAILURE, %zu SHUTDOWN, %zu STOPPED\n", n, shutdown_stamp_ns.size(),
                 stopped_ns.size());
    return out;
  }
  if (stray_stopped) {
    out.stray_stopped = stopped_ns.size() - n;
    std::fprintf(stderr,
                 "%zu STOPPED for %zu SHUTDOWN: the skill's executor stopped the skill on its own (%s says why, e.g. "
                 "CONTROLLER_LOST); the STOPPED figures are left out\n",
                 stopped_ns.size(), n, cell.process("skills").log_path().c_str());
  }
  for (std::size_t i = 0; i < n; ++i) {
    out.shutdown_written_us.push_back(static_cast<double>(shutdown_stamp_ns[i] - failure_ns[i]) / 1000.0);
    out.shutdown_received_us.push_back(static_cast<double>(shutdown_seen_ns[i] - failure_ns[i]) / 1000.0);
    if (stopped_paired) out.stopped_written_us.push_back(static_cast<double>(stopped_ns[i] - failure_ns[i]) / 1000.0);
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

}  // namespace rigger::bench
