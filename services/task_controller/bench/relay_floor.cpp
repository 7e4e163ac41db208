// The floor under the task controller's reaction: a relay that does the hop and nothing else. It reads
// skill events on the controller's reader (same topic, same QoS) and writes the command they cause at
// once on the controller's writers (same topic, same QoS, the executor's partition, the same
// MANUAL_BY_PARTICIPANT lease), woken by a bare Cyclone waitset on a read condition. No engine, no
// journal, no statuses, no announcements: what the hop itself costs, in the same run and against the
// same scripted executors as the controller (task_controller_live_bench runs it after the controller).
//
//   task_controller_relay_floor --pattern failure|success --trials N --trace PATH [--domain D]
//   task_controller_relay_floor --pattern tasks --tasks N --executors E --trials H --trace PATH
//
// failure (the live bench's pattern A): per trial, START Localize on "skills" and TimerMonitor on
//   "monitors"; the monitor's FAILURE -> SHUTDOWN of Localize; its STOPPED -> the next trial.
// success (pattern B): START Pick; its SUCCESS -> START of the next Pick, trials / 2 pairs of them.
// tasks (task_controller_tasks_scale_bench's tasks): N tasks t0..t<N-1> at once, task k on executor
//   ex<k % E> running Step<k % E>; each SUCCESS -> the task's next START, H STARTs per task.
// Task id "relay" (tasks: t0..). The trace is the controller's stage-trace file format (stage_trace.hpp), written at
// the end, so the bench pairs the relay's causes and commands as it pairs the controller's.
// Until an executor has answered once, a START to it is written again every kTick: a volatile reader
// that has not matched our writer yet drops it. Nothing is written again after that; a lost command
// stalls the run and the bench, waiting for this process to end, reports it. Exit 0 when every trial ran.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/skill.hpp"
#include "stage_trace.hpp"

namespace {

using namespace std::chrono_literals;
namespace dds = rigger::dds;
namespace skill = rigger::protocol::skill;
using Clock = std::chrono::steady_clock;

constexpr auto kTick = 20ms;  ///< the waitset's timeout: liveliness assertion and STARTs written again
const std::string kTask = "relay";

const char* option(int argc, char** argv, const char* name, const char* fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
  return fallback;
}

/// The controller's command writer for one executor: commands() with its lease, in that executor's partition.
dds::Writer<rigger_skill_SkillCommand> command_writer(const dds::Participant& p, const std::string& executor_id) {
  dds::Qos q = dds::qos::commands();
  q.manual_liveliness(dds::liveliness_lease());
  dds::set_partitions(q, {skill::command_partition(executor_id)});
  return dds::Writer<rigger_skill_SkillCommand>(p, skill::kCommand, q);
}

enum class Pattern { kFailure, kSuccess, kTasks };

class Relay {
 public:
  /// failure/success: `trials` as the live bench counts them; tasks: `trials` STARTs per task.
  Relay(const dds::Participant& p, Pattern pattern, int trials, int tasks = 1, int executors = 1)
      : participant_(p), pattern_(pattern), events_(p, skill::kEvent) {
    if (pattern == Pattern::kTasks) {
      for (int e = 0; e < executors; ++e) add_executor("ex" + std::to_string(e));
      for (int k = 0; k < tasks; ++k)
        tasks_.push_back({"t" + std::to_string(k), "ex" + std::to_string(k % executors),
                          "Step" + std::to_string(k % executors), 0});
      trials_ = trials;
    } else {
      add_executor("skills");
      if (pattern == Pattern::kFailure) add_executor("monitors");
      trials_ = pattern == Pattern::kFailure ? trials : 2 * std::max(1, trials / 2);
    }
  }

  /// Runs every trial; false when the executors did not match within 10 s.
  bool run(rigger::task_controller::StageTrace& trace) {
    for (auto& [id, writer] : writers_)
      if (!writer.wait_for_readers(1, 10s)) return false;
    if (!events_.wait_for_writers(static_cast<std::uint32_t>(writers_.size()), 10s)) return false;
    const dds_entity_t waitset = dds_create_waitset(participant_.handle());
    const dds_entity_t readable = dds_create_readcondition(events_.handle(), DDS_ANY_STATE);
    dds_waitset_attach(waitset, readable, 0);
    start_trial();
    auto asserted = Clock::now();
    while (!finished()) {
      const dds_return_t n =
          dds_waitset_wait(waitset, nullptr, 0, std::chrono::duration_cast<std::chrono::nanoseconds>(kTick).count());
      if (n > 0) {
        trace.woke();
        events_.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) { on_event(e, trace); });
      }
      if (Clock::now() - asserted >= dds::liveliness_lease() / 3) {
        participant_.assert_liveliness();
        asserted = Clock::now();
      }
      if (n == 0) write_unanswered_again();
    }
    dds_delete(readable);
    dds_delete(waitset);
    return true;
  }

 private:
  struct Task {
    std::string id, executor, skill;
    int started;  ///< STARTs written
  };

  void add_executor(const std::string& id) { writers_.emplace(id, command_writer(participant_, id)); }

  bool finished() const {
    if (pattern_ != Pattern::kTasks) return done_ >= trials_;
    return done_ >= static_cast<int>(tasks_.size());  // tasks whose last START succeeded
  }

  void on_event(const rigger_skill_SkillEvent& e, rigger::task_controller::StageTrace& trace) {
    const std::string executor = dds::to_string(e.executor_id);
    const std::string task = dds::to_string(e.task_id);
    Task* const t = find_task(task);
    if (pattern_ == Pattern::kTasks ? t == nullptr : task != kTask) return;
    answered_.insert(executor);
    const char* kind = e.kind == rigger_skill_SKILL_EVENT_SUCCESS   ? "SUCCESS"
                       : e.kind == rigger_skill_SKILL_EVENT_FAILURE ? "FAILURE"
                       : e.kind == rigger_skill_SKILL_EVENT_STOPPED ? "STOPPED"
                                                                    : nullptr;
    if (kind == nullptr) return;  // ACCEPTED, PROGRESS: nothing to relay
    trace.begin(executor, kind, static_cast<std::int64_t>(e.stamp.sec) * 1000000000LL + e.stamp.nanosec);
    const auto write = [&](rigger_skill_SkillCommandKind k, const std::string& to, const std::string& task_id,
                           const char* node, const char* sk, const char* params) {
      trace.command_writing();
      send(k, to, task_id, node, sk, params);
      trace.command_written();
    };
    if (pattern_ == Pattern::kTasks) {
      if (e.kind == rigger_skill_SKILL_EVENT_SUCCESS && t->started < trials_)
        write(rigger_skill_SKILL_START, t->executor, t->id, ++t->started % 2 ? "step-1" : "step-2",
              t->skill.c_str(), "{}");
      else if (e.kind == rigger_skill_SKILL_EVENT_SUCCESS)
        ++done_;
    } else if (pattern_ == Pattern::kFailure && e.kind == rigger_skill_SKILL_EVENT_FAILURE && executor == "monitors") {
      write(rigger_skill_SKILL_SHUTDOWN, "skills", kTask, "skill", "Localize", "");
    } else if (pattern_ == Pattern::kFailure && e.kind == rigger_skill_SKILL_EVENT_STOPPED && executor == "skills") {
      if (++done_ < trials_) start_trial();
    } else if (pattern_ == Pattern::kSuccess && e.kind == rigger_skill_SKILL_EVENT_SUCCESS && executor == "skills") {
      if (++done_ < trials_) write(rigger_skill_SKILL_START, "skills", kTask, done_ % 2 ? "pick-2" : "pick-1", "Pick", kPick);
    }
    trace.engine_done();
    trace.flushed();
  }

  Task* find_task(const std::string& id) {
    for (Task& t : tasks_)
      if (t.id == id) return &t;
    return nullptr;
  }

  void start_trial() {
    switch (pattern_) {
      case Pattern::kTasks:
        for (Task& t : tasks_) {
          ++t.started;
          send(rigger_skill_SKILL_START, t.executor, t.id, "step-1", t.skill.c_str(), "{}");
        }
        return;
      case Pattern::kSuccess:
        send(rigger_skill_SKILL_START, "skills", kTask, "pick-1", "Pick", kPick);
        return;
      case Pattern::kFailure:
        send(rigger_skill_SKILL_START, "skills", kTask, "skill", "Localize", R"({"object":"load"})");
        send(rigger_skill_SKILL_START, "monitors", kTask, "monitor", "TimerMonitor", R"({"max_duration_s":3600})");
        return;
    }
  }

  void send(rigger_skill_SkillCommandKind kind, const std::string& executor, const std::string& task, const char* node,
            const char* skill_name, const char* params) {
    const std::uint64_t seq = ++seq_;
    const rigger_geometry_Time stamp = dds::wire_now();
    write_command(kind, executor, task, node, skill_name, params, seq, stamp);
    // Kept (as strings) only until the executor first answers: nothing is copied on the measured path.
    if (kind == rigger_skill_SKILL_START && answered_.count(executor) == 0)
      unanswered_[executor + "\t" + task] = {executor, task, node, skill_name, params, seq, stamp};
  }

  struct Unanswered {
    std::string executor, task, node, skill, params;
    std::uint64_t seq;
    rigger_geometry_Time stamp;
  };

  void write_command(rigger_skill_SkillCommandKind kind, const std::string& executor, const std::string& task,
                     const char* node, const char* skill_name, const char* params, std::uint64_t seq,
                     const rigger_geometry_Time& stamp) {
    rigger_skill_SkillCommand c{};
    c.executor_id = dds::wire_string(executor);
    c.task_id = dds::wire_string(task);
    c.node_id = const_cast<char*>(node);
    c.skill = const_cast<char*>(skill_name);
    c.kind = kind;
    c.params_json = const_cast<char*>(params);
    c.reason = const_cast<char*>("");
    c.seq = seq;
    c.stamp = stamp;
    writers_.at(executor).write(c);
  }

  /// The same sample again (same seq and stamp): the executor drops it if the first one came through.
  void write_unanswered_again() {
    for (auto it = unanswered_.begin(); it != unanswered_.end();) {
      if (answered_.count(it->second.executor)) {
        it = unanswered_.erase(it);
        continue;
      }
      const Unanswered& u = it->second;
      write_command(rigger_skill_SKILL_START, u.executor, u.task, u.node.c_str(), u.skill.c_str(), u.params.c_str(),
                    u.seq, u.stamp);
      ++it;
    }
  }

  static constexpr const char* kPick = R"({"object":"load","grasp":"load/grasp_top"})";

  const dds::Participant& participant_;
  const Pattern pattern_;
  int trials_ = 0;  ///< failure: trials; success: events (each SUCCESS but the last causes a START); tasks: per task
  std::map<std::string, dds::Writer<rigger_skill_SkillCommand>> writers_;
  dds::Reader<rigger_skill_SkillEvent> events_;
  std::vector<Task> tasks_;
  std::set<std::string> answered_;  ///< executors that sent an event for the relay's tasks
  std::map<std::string, Unanswered> unanswered_;  ///< by executor and task
  std::uint64_t seq_ = 0;
  int done_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string pattern = option(argc, argv, "--pattern", "");
  const int trials = std::atoi(option(argc, argv, "--trials", "0"));
  const int tasks = std::atoi(option(argc, argv, "--tasks", "1"));
  const int executors = std::atoi(option(argc, argv, "--executors", "1"));
  const std::string trace_path = option(argc, argv, "--trace", "");
  if ((pattern != "failure" && pattern != "success" && pattern != "tasks") || trials < 1 || tasks < 1 ||
      executors < 1 || trace_path.empty()) {
    std::fprintf(stderr,
                 "usage: %s --pattern failure|success|tasks --trials N (>= 1) [--tasks N --executors E] --trace PATH "
                 "[--domain D]\n",
                 argv[0]);
    return 2;
  }
  try {
    // The cell passes the domain both as --domain and as $RIGGER_DOMAIN; the environment is enough.
    const dds::Participant participant(dds::domain_from_environment());
    const Pattern p = pattern == "failure" ? Pattern::kFailure : pattern == "success" ? Pattern::kSuccess : Pattern::kTasks;
    Relay relay(participant, p, trials, tasks, executors);
    rigger::task_controller::StageTrace trace;
    if (!relay.run(trace)) {
      std::fprintf(stderr, "relay_floor: the executors' endpoints did not match within 10 s\n");
      return 1;
    }
    if (!trace.write(trace_path)) {
      std::fprintf(stderr, "relay_floor: could not write the trace %s\n", trace_path.c_str());
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "relay_floor: %s\n", e.what());
    return 1;
  }
}
