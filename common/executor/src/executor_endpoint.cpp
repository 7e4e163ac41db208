#include "rigger/executor/executor_endpoint.hpp"

#include <unistd.h>

#include <algorithm>
#include <stdexcept>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/service_state.hpp"
#include "rigger/protocol/skill.hpp"

namespace rigger::executor {
namespace {

rigger_skill_SkillEventKind to_wire(EventKind k) {
  switch (k) {
    case EventKind::kSuccess: return rigger_skill_SKILL_EVENT_SUCCESS;
    case EventKind::kFailure: return rigger_skill_SKILL_EVENT_FAILURE;
    case EventKind::kStopped: return rigger_skill_SKILL_EVENT_STOPPED;
    case EventKind::kProgress: return rigger_skill_SKILL_EVENT_PROGRESS;
  }
  return rigger_skill_SKILL_EVENT_FAILURE;
}

std::string host_name() {
  char buf[256] = {};
  return gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string("unknown");
}

}  // namespace

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::kSuccess: return "SUCCESS";
    case EventKind::kFailure: return "FAILURE";
    case EventKind::kStopped: return "STOPPED";
    case EventKind::kProgress: return "PROGRESS";
  }
  return "?";
}

ExecutorEndpoint::ExecutorEndpoint(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                   std::string executor_id, nlohmann::json library, Handlers handlers)
    : loop_(loop),
      log_(std::move(log)),
      executor_id_(std::move(executor_id)),
      library_(std::move(library)),
      handlers_(std::move(handlers)),
      host_(host_name()),
      announcements_(participant, protocol::skill::kExecutors),
      events_(participant, protocol::skill::kEvent),
      commands_(participant, protocol::skill::kCommand) {
  if (!library_.is_object() || !library_.contains("skills") || !library_["skills"].is_array())
    throw std::invalid_argument("executor " + executor_id_ + ": the skill library needs a \"skills\" array");
  for (const auto& s : library_["skills"])
    if (s.is_object() && s.contains("name") && s["name"].is_string()) skill_names_.push_back(s["name"]);
  library_text_ = library_.dump();
  loop_.on_data(commands_, [this] { on_commands(); });
  // See ServiceAnnouncer::reannounce(): a reader that expired our lease sees us again on a new sample.
  refresh_timer_ = loop_.every(dds::kServiceRefreshPeriod, [this] { announce(); });
  loop_.on_status(announcements_.handle(), DDS_LIVELINESS_LOST_STATUS, [this] { announce(); });
  announce();
}

ExecutorEndpoint::~ExecutorEndpoint() {
  loop_.cancel(refresh_timer_);
  rigger_skill_ExecutorAnnouncement key{};
  key.executor_id = dds::wire_string(executor_id_);
  key.host = dds::wire_string(host_);
  key.library_json = dds::wire_string("");
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
  if (announcements_.write(a) != DDS_RETCODE_OK) log_->warn("announcement write failed executor={}", executor_id_);
}

std::vector<LeafRun> ExecutorEndpoint::active_runs() const {
  std::vector<LeafRun> out;
  for (const auto& [key, seq] : active_) out.push_back({key.first, key.second, seq});
  return out;
}

void ExecutorEndpoint::on_commands() {
  commands_.take([this](const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info) { handle(cmd, info); });
}

void ExecutorEndpoint::handle(const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info) {
  if (dds::to_string(cmd.executor_id) != executor_id_) return;
  const std::string task = dds::to_string(cmd.task_id), node = dds::to_string(cmd.node_id);
  auto& last = last_seq_by_writer_[info.publication_handle];
  if (cmd.seq <= last) {
    log_->warn("command dropped reason=stale_or_duplicate seq={} last_seq={} task={} node={}", cmd.seq, last, task, node);
    return;
  }
  last = cmd.seq;
  const auto key = std::make_pair(task, node);

  if (cmd.kind == rigger_skill_SKILL_SHUTDOWN) {
    auto it = active_.find(key);
    if (it == active_.end()) {
      // Not running here (already ended, or never started): acknowledge at once.
      const LeafRun run{task, node, 0};
      active_[key] = 0;
      report(run, EventKind::kStopped, "NOT_RUNNING", "no such run on executor " + executor_id_);
      return;
    }
    log_->info("shutdown task={} node={} reason={}", task, node, dds::to_string(cmd.reason));
    if (handlers_.on_shutdown) handlers_.on_shutdown({{task, node, it->second}, dds::to_string(cmd.reason)});
    return;
  }

  if (active_.count(key)) {
    log_->warn("start dropped reason=already_running task={} node={} seq={}", task, node, cmd.seq);
    return;
  }
  const LeafRun run{task, node, cmd.seq};
  active_[key] = cmd.seq;
  const std::string skill = dds::to_string(cmd.skill);
  nlohmann::json params;
  try {
    const std::string text = dds::to_string(cmd.params_json);
    params = text.empty() ? nlohmann::json::object() : nlohmann::json::parse(text);
    if (!params.is_object()) throw std::invalid_argument("params must be a JSON object");
  } catch (const std::exception& e) {
    report(run, EventKind::kFailure, "BAD_PARAMS", std::string("params of ") + skill + " unreadable: " + e.what());
    return;
  }
  if (std::find(skill_names_.begin(), skill_names_.end(), skill) == skill_names_.end()) {
    report(run, EventKind::kFailure, "UNKNOWN_SKILL", "executor " + executor_id_ + " does not offer " + skill);
    return;
  }
  log_->info("start task={} node={} skill={} seq={}", task, node, skill, cmd.seq);
  if (handlers_.on_start) handlers_.on_start({run, skill, std::move(params)});
}

bool ExecutorEndpoint::report(const LeafRun& run, EventKind kind, const std::string& code, const std::string& message,
                              double progress) {
  const auto key = std::make_pair(run.task_id, run.node_id);
  auto it = active_.find(key);
  if (it == active_.end() || it->second != run.start_seq) {
    log_->warn("report dropped reason=run_not_active task={} node={} kind={}", run.task_id, run.node_id, to_string(kind));
    return false;
  }
  rigger_skill_SkillEvent ev{};
  ev.executor_id = dds::wire_string(executor_id_);
  ev.task_id = dds::wire_string(run.task_id);
  ev.node_id = dds::wire_string(run.node_id);
  ev.kind = to_wire(kind);
  ev.code = dds::wire_string(code);
  ev.message = dds::wire_string(message);
  ev.progress = progress;
  ev.seq = ++event_seq_;
  ev.command_seq = run.start_seq;
  ev.stamp = dds::wire_now();
  if (kind != EventKind::kProgress) active_.erase(it);
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

}  // namespace rigger::executor
