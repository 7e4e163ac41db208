#include "rigger/skill_protocol/executor_endpoint.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <stdexcept>

#include "rigger/base/bounded_json.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::skill_protocol {
namespace {

/// A START's parameters: one skill's values (poses, a screw list), far below a recipe's 4 MiB.
constexpr rigger::JsonLimits kParamsLimits{256U * 1024U, 32};

std::string host_name() {
  char buf[256] = {};
  return gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string("unknown");
}

}  // namespace

ExecutorEndpoint::ExecutorEndpoint(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                   std::string executor_id, nlohmann::json library, Handlers handlers, Options options)
    : loop_(loop),
      log_(std::move(log)),
      executor_id_(std::move(executor_id)),
      library_(std::move(library)),
      handlers_(std::move(handlers)),
      options_(options),
      host_(host_name()),
      announcements_(participant, protocol::skill::kExecutors),
      events_(participant, protocol::skill::kEvent),
      commands_(participant, protocol::skill::kCommand, dds::qos::executor_commands(executor_id_)) {
  if (!library_.is_object() || !library_.contains("skills") || !library_["skills"].is_array())
    throw std::invalid_argument("executor " + executor_id_ + ": the skill library needs a \"skills\" array");
  for (const auto& s : library_["skills"]) {
    if (!s.is_object() || !s.contains("name") || !s["name"].is_string()) continue;
    skill_names_.push_back(s["name"]);
    if (auto parsed = skill::parse_description(s); parsed.ok()) descriptions_.emplace(s["name"], *parsed.value);
  }
  library_text_ = library_.dump();
  loop_.on_data_now(commands_, [this] { on_commands(); });
  loop_.on_status(commands_.handle(), DDS_LIVELINESS_CHANGED_STATUS, [this] { on_commander_liveliness(); });
  // See ServiceAnnouncer::reannounce(): a reader that expired our lease sees us again on a new sample.
  // The same timer re-reads the command writers' liveliness while runs are active: a backstop should a
  // status change not wake the loop.
  refresh_timer_ = loop_.every(service::kServiceRefreshPeriod, [this] {
    announce();
    if (!active_.empty()) on_commander_liveliness();
  });
  loop_.on_status(announcements_.handle(), DDS_LIVELINESS_LOST_STATUS, [this] { announce(); });
  announce();
}

ExecutorEndpoint::~ExecutorEndpoint() {
  loop_.cancel(refresh_timer_);
  if (announce_timer_ != 0) loop_.cancel(announce_timer_);
  for (const auto& w : waiting_) loop_.cancel(w.deadline);
  rigger_skill_ExecutorAnnouncement key{};
  const std::string empty;
  key.executor_id = dds::wire_string(executor_id_);
  key.host = dds::wire_string(host_);
  key.library_json = dds::wire_string(empty);
  announcements_.unregister(key);
}

void ExecutorEndpoint::announce() {
  rigger_skill_ExecutorAnnouncement a{};
  a.executor_id = dds::wire_string(executor_id_);
  a.host = dds::wire_string(host_);
  a.pid = static_cast<int32_t>(getpid());
  std::vector<char*> names;
  dds::wire_string_sequence(a.skills, skill_names_, names);
  a.library_json = dds::wire_string(library_text_);
  a.stamp = dds::wire_now();
  const std::vector<AnnouncedRun> runs = announced_runs();
  WireRuns storage;
  wire_runs(a, runs, storage);
  if (announcements_.write(a) != DDS_RETCODE_OK) log_->warn("announcement write failed executor={}", executor_id_);
}

void ExecutorEndpoint::announce_soon() {
  // The announcement carries the whole library: written at once, it went out right behind the event or
  // the START's answer and took the CPU from whoever handles them (on 2 cores, the controller and the
  // next command's receiver; here, the skill's own SHUTDOWN handler). Runs that change within the delay
  // share one announcement, written after their events (so a reader of it has their ends first).
  if (announce_timer_ != 0) return;
  announce_timer_ = loop_.after(kAnnounceDelay, [this] {
    announce_timer_ = 0;
    announce();
  });
}

std::vector<LeafRun> ExecutorEndpoint::active_runs() const {
  std::vector<LeafRun> out;
  for (const auto& [key, run] : active_) out.push_back({key.first, key.second, run.start_seq});
  return out;
}

std::vector<AnnouncedRun> ExecutorEndpoint::announced_runs() const {
  std::vector<AnnouncedRun> out;
  for (const auto& [key, run] : active_) out.push_back({key.first, key.second, run.skill, run.resources, run.stopping});
  return out;
}

std::vector<std::string> ExecutorEndpoint::resources_of(const std::string& skill, const nlohmann::json& params) const {
  const auto it = descriptions_.find(skill);
  return it == descriptions_.end() ? std::vector<std::string>{} : skill::resolve_resources(it->second, params);
}

void ExecutorEndpoint::on_commands() {
  if (!options_.on_received) {
    commands_.take([this](const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info) { handle(cmd, info); });
    return;
  }
  const std::int64_t woke =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  commands_.take([this, woke](const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info) {
    options_.on_received(cmd, woke);
    handle(cmd, info);
  });
}

std::optional<dds_guid_t> ExecutorEndpoint::writer_participant(dds_instance_handle_t writer) const {
  dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(commands_.handle(), writer);
  if (e == nullptr) return std::nullopt;
  const dds_guid_t participant = e->participant_key;
  dds_builtintopic_free_endpoint(e);
  return participant;
}

void ExecutorEndpoint::on_commander_liveliness() {
  dds_liveliness_changed_status_t st{};
  if (dds_get_liveliness_changed_status(commands_.handle(), &st) != DDS_RETCODE_OK) return;
  if (st.alive_count_change != 0 || st.not_alive_count_change != 0)
    log_->info("command writers' liveliness changed: alive {} ({:+d}), not alive {} ({:+d}), last writer {:x}",
               st.alive_count, st.alive_count_change, st.not_alive_count, st.not_alive_count_change,
               st.last_publication_handle);
  // With no command writer alive, every run lost its commander, whatever the changes since the last read
  // say: a writer that came back alive and was lost again between two reads nets to no change (seen in
  // bench_safe_stop after this executor had been frozen: the next controller's kill went unnoticed).
  // Otherwise a writer was lost when the counts say so, and the status names the last one that changed.
  const bool all_lost = st.alive_count == 0;
  if (!all_lost && st.alive_count_change >= 0 && st.not_alive_count_change <= 0) return;  // a writer appeared
  // A run's commander is lost with the writer that started it, and with any other writer of the same
  // participant: a controller's writers share its asserted liveliness, so one lapse means the process
  // stopped asserting. (The status reports each writer's lapse on its own: under load the second came
  // 706 ms after the first, and a run started by it kept the robot moving that long.)
  const std::optional<dds_guid_t> lost_participant = writer_participant(st.last_publication_handle);
  const auto commander_lost = [&](dds_instance_handle_t commander) {
    if (all_lost || commander == st.last_publication_handle) return true;
    if (!lost_participant) return false;
    const std::optional<dds_guid_t> p = writer_participant(commander);
    return p && std::memcmp(p->v, lost_participant->v, sizeof p->v) == 0;
  };
  // Chosen first, shut down after: a skill that stops at once reports its end from inside on_shutdown,
  // which erases its run from active_ (iterating active_ meanwhile crashed the executor).
  std::vector<LeafRun> lost;
  for (auto& [key, run] : active_) {
    if (run.stopping || !commander_lost(run.commander)) continue;
    run.stopping = true;
    lost.push_back({key.first, key.second, run.start_seq});
  }
  if (!lost.empty()) announce();
  for (const LeafRun& run : lost) {
    log_->warn("shutdown task={} node={} reason=CONTROLLER_LOST (the command writer's liveliness was lost)",
               run.task_id, run.node_id);
    if (handlers_.on_shutdown) handlers_.on_shutdown({run, "CONTROLLER_LOST: the task controller was lost"});
  }
  // Waiting STARTs of a lost controller start nothing.
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    if (commander_lost(it->commander)) {
      loop_.cancel(it->deadline);
      refuse(it->run, "CONTROLLER_LOST", "the task controller was lost before " + it->skill + " could start");
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
}

bool CommandOrder::accept(std::uint64_t seq, std::uint64_t* last) {
  const std::uint64_t newest = seen_.empty() ? 0 : *seen_.rbegin();
  if (last) *last = newest;
  if (seq == 0) return false;
  // The set holds every seq taken from its smallest on: below that, a full window cannot tell.
  if (seen_.size() >= kWindow && seq < *seen_.begin()) return false;
  if (!seen_.insert(seq).second) return false;
  if (seen_.size() > kWindow) seen_.erase(seen_.begin());
  return true;
}

void ExecutorEndpoint::handle(const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info) {
  if (dds::to_string(cmd.executor_id) != executor_id_) return;
  const std::string task = dds::to_string(cmd.task_id), node = dds::to_string(cmd.node_id);
  std::uint64_t last = 0;
  if (!order_by_writer_[info.publication_handle].accept(cmd.seq, &last)) {
    log_->warn("command dropped reason=stale_or_duplicate seq={} last_seq={} task={} node={}", cmd.seq, last, task,
               node);
    return;
  }
  if (cmd.seq < last)
    log_->info("command taken out of order seq={} last_seq={} task={} node={} (sent again)", cmd.seq, last, task, node);
  const auto key = std::make_pair(task, node);

  if (cmd.kind == rigger_skill_SKILL_SHUTDOWN) {
    // A START of this node still waiting here never ran: it is stopped at once.
    for (auto w = waiting_.begin(); w != waiting_.end(); ++w) {
      if (w->run.task_id != task || w->run.node_id != node) continue;
      loop_.cancel(w->deadline);
      const LeafRun run = w->run;
      waiting_.erase(w);
      write_event(run, EventKind::kStopped, "NOT_STARTED", "stopped before it started on executor " + executor_id_,
                  -1.0);
      return;
    }
    auto it = active_.find(key);
    if (it == active_.end()) {
      // Not running here (already ended, or never started): acknowledge at once.
      write_event({task, node, 0}, EventKind::kStopped, "NOT_RUNNING", "no such run on executor " + executor_id_, -1.0);
      return;
    }
    log_->info("shutdown task={} node={} reason={}", task, node, dds::to_string(cmd.reason));
    const bool was_stopping = it->second.stopping;
    it->second.stopping = true;
    it->second.stopped_for_pause = false;  // the controller asked for the stop now: STOPPED answers it
    if (!was_stopping) announce_soon();
    if (handlers_.on_shutdown) handlers_.on_shutdown({{task, node, it->second.start_seq}, dds::to_string(cmd.reason)});
    return;
  }

  if (cmd.kind == rigger_skill_SKILL_PAUSE || cmd.kind == rigger_skill_SKILL_RESUME) {
    handle_pause(task, node, cmd.kind == rigger_skill_SKILL_PAUSE, dds::to_string(cmd.reason));
    return;
  }
  if (cmd.kind != rigger_skill_SKILL_START) {
    log_->warn("command dropped reason=unknown_kind kind={} task={} node={}", static_cast<int>(cmd.kind), task, node);
    return;
  }

  Start start{{task, node, cmd.seq},
              dds::to_string(cmd.skill),
              nlohmann::json::object(),
              {},
              info.publication_handle,
              0,
              false};
  if (cmd.params_json != nullptr && cmd.params_json[0] != '\0') {
    // Parameters come from another process: bounded while parsed (size first, then depth, UTF-8, keys).
    auto parsed = rigger::parse_json_bounded(cmd.params_json, kParamsLimits);
    if (!parsed.ok()) {
      refuse(start.run, "BAD_PARAMS", "params of " + start.skill + " unreadable: " + parsed.error->to_string());
      return;
    }
    start.params = std::move(parsed.value);
  }
  if (!start.params.is_object()) {
    refuse(start.run, "BAD_PARAMS",
           "params of " + start.skill + " must be a JSON object, got " + std::string(start.params.type_name()));
    return;
  }
  if (std::find(skill_names_.begin(), skill_names_.end(), start.skill) == skill_names_.end()) {
    refuse(start.run, "UNKNOWN_SKILL", "executor " + executor_id_ + " does not offer " + start.skill);
    return;
  }
  start.resources = resources_of(start.skill, start.params);
  handle_start(std::move(start));
}

void ExecutorEndpoint::handle_pause(const std::string& task, const std::string& node, bool pause,
                                    const std::string& reason) {
  const EventKind kind = pause ? EventKind::kPaused : EventKind::kResumed;
  // A START of the node waiting here is newer than a run of the node still stopping: the PAUSE is its.
  for (auto w = waiting_.begin(); w != waiting_.end(); ++w) {
    if (w->run.task_id != task || w->run.node_id != node) continue;
    if (std::string why = pause ? stops_for_pause(w->skill, w->resources) : ""; !why.empty()) {
      // It could not start paused: it never starts.
      loop_.cancel(w->deadline);
      const LeafRun run = w->run;
      waiting_.erase(w);
      log_->warn("pause task={} node={} code=NOT_PAUSABLE_STOPPED {}; it was waiting to start: not started", task, node,
                 why);
      write_event(run, kind, "NOT_PAUSABLE_STOPPED", why + "; it was waiting to start: it will not start", -1.0);
      write_event(run, EventKind::kFailure, "NOT_PAUSABLE", "could not pause: " + why + "; it never started", -1.0);
      return;
    }
    if (std::string why = not_pausable(w->skill); !why.empty()) {
      write_event(w->run, kind, "NOT_PAUSABLE", why, -1.0);
      return;
    }
    w->paused = pause;
    write_event(w->run, kind, "",
                w->skill + (pause ? " will start paused" : " will start running") + " on executor " + executor_id_,
                -1.0);
    return;
  }
  const RunKey key{task, node};
  auto it = active_.find(key);
  if (it == active_.end()) {
    write_event({task, node, 0}, kind, "NOT_RUNNING", "no such run on executor " + executor_id_, -1.0);
    return;
  }
  const LeafRun run{task, node, it->second.start_seq};
  if (std::string why = pause && !it->second.stopping ? stops_for_pause(it->second.skill, it->second.resources) : "";
      !why.empty()) {
    // The answer first, then the safe stop: the skill may end inside on_shutdown.
    it->second.stopping = true;
    it->second.stopped_for_pause = true;
    log_->warn("pause task={} node={} code=NOT_PAUSABLE_STOPPED {}", task, node, why);
    write_event(run, kind, "NOT_PAUSABLE_STOPPED", why, -1.0);
    announce_soon();
    if (handlers_.on_shutdown) handlers_.on_shutdown({run, "PAUSE: " + why});
    return;
  }
  const PauseAnswer answer = pause_run(key, pause, reason);
  if (active_.count(key) == 0) return;  // the skill ended inside the call: its end is the answer
  log_->info("{} task={} node={} code={} reason={}", pause ? "pause" : "resume", task, node, answer.code, reason);
  write_event(run, kind, answer.code, answer.message, -1.0);
}

std::string ExecutorEndpoint::not_pausable(const std::string& skill) const {
  const auto d = descriptions_.find(skill);
  if (d != descriptions_.end() && d->second.pausable && handlers_.on_pause) return "";
  const bool monitor = d != descriptions_.end() && d->second.kind == skill::SkillKind::kMonitor;
  return skill + " cannot pause: it keeps " + (monitor ? "monitoring" : "running");
}

std::string ExecutorEndpoint::stops_for_pause(const std::string& skill,
                                              const std::vector<std::string>& resources) const {
  if (not_pausable(skill).empty()) return "";
  const auto d = descriptions_.find(skill);
  if (d == descriptions_.end() || d->second.kind == skill::SkillKind::kMonitor) return "";
  std::string devices;
  for (const auto& r : resources)
    if (std::find(safety::stoppable_resources().begin(), safety::stoppable_resources().end(), r) !=
        safety::stoppable_resources().end())
      devices += (devices.empty() ? "" : ", ") + r;
  if (devices.empty()) return "";
  return skill + " cannot pause and holds " + devices + ": it is brought to its safe stop";
}

PauseAnswer ExecutorEndpoint::pause_run(const RunKey& key, bool pause, const std::string& reason) {
  const Active& a = active_.at(key);
  const std::string skill = a.skill;  // `a` may be gone after the handler (a skill that ends at once)
  if (a.stopping) return {"STOPPING", skill + " is being stopped: its safe stop proceeds"};
  if (std::string why = not_pausable(skill); !why.empty()) return {"NOT_PAUSABLE", why};
  if (a.paused == pause)
    return {pause ? "ALREADY_PAUSED" : "NOT_PAUSED", skill + " was " + (pause ? "" : "not ") + "paused"};
  PauseAnswer answer = handlers_.on_pause({{key.first, key.second, a.start_seq}, pause, reason});
  auto it = active_.find(key);
  if (it != active_.end() && answer.code.empty()) it->second.paused = pause;
  answer.message = skill + " " + answer.message;
  return answer;
}

std::string ExecutorEndpoint::blocked(const Start& start, bool& wait) const {
  wait = true;
  std::string why;
  for (const auto& [key, run] : active_) {
    std::string clash;
    if (key.first == start.run.task_id && key.second == start.run.node_id) {
      clash = "its previous run";
    } else {
      for (const auto& r : start.resources)
        if (std::find(run.resources.begin(), run.resources.end(), r) != run.resources.end()) {
          clash = "resource '" + r + "', held by " + run.skill + " (task " + key.first + ", node " + key.second + ")";
          break;
        }
    }
    if (clash.empty()) continue;
    wait = wait && run.stopping;
    if (!why.empty()) why += "; ";
    why += clash + (run.stopping ? " still stopping" : " running");
  }
  return why;
}

void ExecutorEndpoint::handle_start(Start start) {
  bool wait = false;
  const std::string why = blocked(start, wait);
  if (why.empty()) {
    dispatch(std::move(start));
    return;
  }
  if (!wait) {
    refuse_blocked(start, why);
    return;
  }
  log_->info("start waits task={} node={} skill={} seq={} for=\"{}\"", start.run.task_id, start.run.node_id,
             start.skill, start.run.start_seq, why);
  const LeafRun run = start.run;
  write_event(run, EventKind::kAccepted, "WAITING", start.skill + " waits on executor " + executor_id_ + " for " + why,
              -1.0);
  start.deadline = loop_.after(options_.start_wait, [this, run] {
    for (auto w = waiting_.begin(); w != waiting_.end(); ++w) {
      if (w->run.task_id != run.task_id || w->run.node_id != run.node_id || w->run.start_seq != run.start_seq) continue;
      bool ignored = false;
      const std::string still = blocked(*w, ignored);
      const std::string skill = w->skill;
      waiting_.erase(w);
      refuse(run, "STILL_STOPPING",
             skill + " waited " + std::to_string(options_.start_wait.count()) + " ms on executor " + executor_id_ +
                 " for " + still);
      return;
    }
  });
  waiting_.push_back(std::move(start));
}

void ExecutorEndpoint::start_waiting() {
  for (auto w = waiting_.begin(); w != waiting_.end();) {
    bool wait = false;
    const std::string why = blocked(*w, wait);
    if (!why.empty() && wait) {
      ++w;
      continue;
    }
    Start start = std::move(*w);
    w = waiting_.erase(w);
    loop_.cancel(start.deadline);
    if (why.empty()) {
      dispatch(std::move(start));
    } else {  // what it waited for has stopped, but a run that started meanwhile holds it now
      refuse_blocked(start, why);
    }
    w = waiting_.begin();  // a dispatch may have claimed resources others wait for: look again from the front
  }
}

void ExecutorEndpoint::dispatch(Start start) {
  active_[{start.run.task_id, start.run.node_id}] =
      Active{start.run.start_seq, start.skill, start.resources, start.commander, false, false};
  log_->info("start task={} node={} skill={} seq={}", start.run.task_id, start.run.node_id, start.skill,
             start.run.start_seq);
  write_event(start.run, EventKind::kAccepted, "", start.skill + " runs on executor " + executor_id_, -1.0);
  announce_soon();
  const RunKey key{start.run.task_id, start.run.node_id};
  const bool paused = start.paused;
  if (handlers_.on_start) handlers_.on_start({start.run, start.skill, std::move(start.params)});
  // Paused while it waited (already answered): it holds from its start.
  if (paused && active_.count(key) != 0) {
    const PauseAnswer answer = pause_run(key, true, "paused while it waited");
    if (!answer.code.empty())
      log_->warn("start paused failed task={} node={} code={} {}", key.first, key.second, answer.code, answer.message);
  }
}

void ExecutorEndpoint::refuse_blocked(const Start& start, const std::string& why) {
  const bool same_node = active_.count({start.run.task_id, start.run.node_id}) > 0;
  refuse(start.run, same_node ? "ALREADY_RUNNING" : "RESOURCE_BUSY",
         start.skill + " cannot start on executor " + executor_id_ + ": " + why);
}

void ExecutorEndpoint::refuse(const LeafRun& run, const std::string& code, const std::string& message) {
  write_event(run, EventKind::kFailure, code, message, -1.0);
}

bool ExecutorEndpoint::report(const LeafRun& run, EventKind kind, const std::string& code, const std::string& message,
                              double progress) {
  if (kind == EventKind::kAccepted || kind == EventKind::kPaused || kind == EventKind::kResumed) {
    log_->warn("report dropped reason=answers_are_the_endpoints task={} node={} kind={}", run.task_id, run.node_id,
               to_string(kind));
    return false;
  }
  const auto key = std::make_pair(run.task_id, run.node_id);
  auto it = active_.find(key);
  if (it == active_.end() || it->second.start_seq != run.start_seq) {
    log_->warn("report dropped reason=run_not_active task={} node={} kind={}", run.task_id, run.node_id,
               to_string(kind));
    return false;
  }
  // A run a PAUSE stopped (not pausable) did not pause: its stop is a FAILURE of its node, which the
  // controller never asked to stop.
  const bool not_paused = kind == EventKind::kStopped && it->second.stopped_for_pause;
  if (kind != EventKind::kProgress) active_.erase(it);
  const bool written =
      not_paused ? write_event(run, EventKind::kFailure, "NOT_PAUSABLE", "could not pause: " + message, progress)
                 : write_event(run, kind, code, message, progress);
  // After the event: whoever reads an announcement without the run has the run's end written before it.
  if (kind != EventKind::kProgress) announce_soon();
  if (kind != EventKind::kProgress && !waiting_.empty()) loop_.post([this] { start_waiting(); });
  return written;
}

bool ExecutorEndpoint::write_event(const LeafRun& run, EventKind kind, const std::string& code,
                                   const std::string& message, double progress) {
  rigger_skill_SkillEvent ev{};
  ev.executor_id = dds::wire_string(executor_id_);
  ev.task_id = dds::wire_string(run.task_id);
  ev.node_id = dds::wire_string(run.node_id);
  const LeafOutcome outcome{kind, code, message, progress < 0.0 ? std::nullopt : std::optional<double>(progress)};
  to_wire(outcome, ev);
  ev.seq = ++event_seq_;
  ev.command_seq = run.start_seq;
  ev.stamp = dds::wire_now();
  const auto rc = events_.write(ev);
  if (rc != DDS_RETCODE_OK) {
    log_->error("event write failed task={} node={} kind={} rc={}", run.task_id, run.node_id, to_string(kind), rc);
    return false;
  }
  if (kind != EventKind::kProgress)
    log_->info("event task={} node={} kind={} code={} message=\"{}\"", run.task_id, run.node_id, to_string(kind), code,
               message);
  return true;
}

void wire_runs(rigger_skill_ExecutorAnnouncement& announcement, const std::vector<AnnouncedRun>& runs,
               WireRuns& storage) {
  storage.runs.assign(runs.size(), rigger_skill_ExecutorRun{});
  storage.resources.assign(runs.size(), {});
  for (std::size_t i = 0; i < runs.size(); ++i) {
    auto& w = storage.runs[i];
    w.task_id = dds::wire_string(runs[i].task_id);
    w.node_id = dds::wire_string(runs[i].node_id);
    w.skill = dds::wire_string(runs[i].skill);
    dds::wire_string_sequence(w.resources, runs[i].resources, storage.resources[i]);
    w.stopping = runs[i].stopping;
  }
  dds::wire_sequence(announcement.runs, storage.runs);
}

std::vector<AnnouncedRun> runs_of(const rigger_skill_ExecutorAnnouncement& announcement) {
  std::vector<AnnouncedRun> out;
  for (const auto& w : dds::elements(announcement.runs))
    out.push_back({dds::to_string(w.task_id), dds::to_string(w.node_id), dds::to_string(w.skill),
                   dds::to_string_vector(w.resources), w.stopping});
  return out;
}

}  // namespace rigger::skill_protocol
