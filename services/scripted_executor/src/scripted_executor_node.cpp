#include "scripted_executor_node.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"

namespace rigger::scripted {
namespace {

/// The receipt trace holds at most this many commands and events (a benchmark's thousands of trials fit).
constexpr std::size_t kReceiptCapacity = 1U << 18;

std::int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

ScriptedExecutorNode::ScriptedExecutorNode(service::ServiceContext& ctx) : ctx_(ctx) {
  ScriptedExecutorSettings settings = read_settings(ctx.config, scripted_executor_settings());
  nlohmann::json library = std::move(settings.library);
  const std::size_t announced = library["skills"].size();
  is_monitor_ = std::move(settings.is_monitor);
  default_skill_ = settings.default_skill;
  default_monitor_ = settings.default_monitor;
  by_skill_ = std::move(settings.by_skill);
  by_node_ = std::move(settings.by_node);
  receipt_trace_path_ = std::move(settings.receipt_trace_path);

  skill_protocol::ExecutorEndpoint::Options options;
  if (!receipt_trace_path_.empty()) {
    receipts_.reserve(kReceiptCapacity);
    options.on_received = [this](const rigger_skill_SkillCommand& c, std::int64_t woke_wall_ns) {
      if (receipts_.size() < kReceiptCapacity)
        receipts_.push_back({dds::to_string(c.executor_id), static_cast<int>(c.kind), dds::to_string(c.task_id),
                             dds::to_string(c.node_id),
                             static_cast<std::int64_t>(c.stamp.sec) * 1000000000LL + c.stamp.nanosec, woke_wall_ns});
    };
  }
  endpoint_ = std::make_unique<skill_protocol::ExecutorEndpoint>(
      ctx.participant, ctx.loop, ctx.log, ctx.options.id, library,
      skill_protocol::ExecutorEndpoint::Handlers{[this](const skill_protocol::StartRequest& r) { on_start(r); },
                                                 [this](const skill_protocol::ShutdownRequest& r) { on_shutdown(r); }},
      std::move(options));
  ctx.log->info("scripted executor ready skills={}", announced);
}

ScriptedExecutorNode::~ScriptedExecutorNode() {
  for (auto& [key, a] : active_)
    for (auto t : a.timers) ctx_.loop.cancel(t);
  if (receipt_trace_path_.empty()) return;
  std::ofstream out(receipt_trace_path_);
  out << "executor\tkind\ttask\tnode\tstamp_wall_ns\twoke_wall_ns\n";
  for (const auto& r : receipts_)
    out << r.executor_id << '\t' << r.kind << '\t' << r.task_id << '\t' << r.node_id << '\t' << r.stamp_wall_ns << '\t' << r.woke_wall_ns
        << '\n';
  out.flush();
  if (!out) ctx_.log->error("could not write the receipt trace {}", receipt_trace_path_);
}

const Behaviour& ScriptedExecutorNode::behaviour_for(const std::string& skill, const std::string& node_id) const {
  if (auto n = by_node_.find(node_id); n != by_node_.end()) return n->second;
  if (auto s = by_skill_.find(skill); s != by_skill_.end()) return s->second;
  auto m = is_monitor_.find(skill);
  return m != is_monitor_.end() && m->second ? default_monitor_ : default_skill_;
}

void ScriptedExecutorNode::on_start(const skill_protocol::StartRequest& request) {
  const Key key{request.run.task_id, request.run.node_id};
  const Behaviour& b = behaviour_for(request.skill, request.run.node_id);
  ctx_.log->info("start task={} node={} skill={} mode={} delay_s={}", key.first, key.second, request.skill,
                 to_string(b.mode), b.delay_s);
  // A restart of the same node (Retry) replaces the previous run's leftovers.
  if (auto old = active_.find(key); old != active_.end()) {
    for (auto t : old->second.timers) ctx_.loop.cancel(t);
    active_.erase(old);
  }
  Active& a = active_[key];
  a.run = request.run;
  a.behaviour = b;
  const auto start_seq = request.run.start_seq;
  for (unsigned i = 1; i <= b.progress_steps; ++i) {
    const double fraction = static_cast<double>(i) / (b.progress_steps + 1);
    a.timers.push_back(ctx_.loop.after(from_seconds(b.delay_s * fraction), [this, key, fraction, start_seq] {
      auto it = active_.find(key);
      if (it == active_.end() || it->second.run.start_seq != start_seq || it->second.stopping) return;
      endpoint_->report(it->second.run, skill_protocol::EventKind::kProgress, "", "scripted progress", fraction);
    }));
  }
  if (b.mode == Mode::kRun) return;
  a.timers.push_back(ctx_.loop.after(from_seconds(b.delay_s), [this, key, start_seq] {
    auto it = active_.find(key);
    if (it == active_.end() || it->second.run.start_seq != start_seq || it->second.stopping) return;
    const Behaviour& beh = it->second.behaviour;
    switch (beh.mode) {
      case Mode::kSucceed:
        finish(key, skill_protocol::EventKind::kSuccess, "", beh.message);
        break;
      case Mode::kFail:
        finish(key, skill_protocol::EventKind::kFailure, beh.code, beh.message);
        break;
      case Mode::kCrash:
        ctx_.log->warn("scripted crash task={} node={}", key.first, key.second);
        ctx_.log->flush();
        std::abort();
      case Mode::kHang:
        ctx_.log->warn("scripted hang task={} node={}: blocking the event loop", key.first, key.second);
        ctx_.log->flush();
        // Block the loop thread for good: no liveliness assertion, no events. Signals still end
        // the process (run_service's handler stops the loop, which never returns here: the test kills us).
        for (;;) ::pause();
      case Mode::kRun: break;
    }
  }));
}

void ScriptedExecutorNode::on_shutdown(const skill_protocol::ShutdownRequest& request) {
  const Key key{request.run.task_id, request.run.node_id};
  auto it = active_.find(key);
  if (it == active_.end()) return;
  Active& a = it->second;
  ctx_.log->info("shutdown task={} node={} reason={} never_stop={} stop_delay_s={}", key.first, key.second,
                 request.reason, a.behaviour.never_stop, a.behaviour.stop_delay_s);
  if (a.behaviour.never_stop || a.stopping) return;
  a.stopping = true;
  for (auto t : a.timers) ctx_.loop.cancel(t);
  a.timers.clear();
  if (a.behaviour.stop_delay_s <= 0.0) {
    finish(key, skill_protocol::EventKind::kStopped, "", "stopped");
    return;
  }
  const auto start_seq = a.run.start_seq;
  a.timers.push_back(ctx_.loop.after(from_seconds(a.behaviour.stop_delay_s), [this, key, start_seq] {
    auto i = active_.find(key);
    if (i == active_.end() || i->second.run.start_seq != start_seq) return;
    finish(key, skill_protocol::EventKind::kStopped, "", "stopped after a slow stop");
  }));
}

void ScriptedExecutorNode::finish(const Key& key, skill_protocol::EventKind kind, std::string code,
                                  std::string message) {
  auto it = active_.find(key);
  if (it == active_.end()) return;
  const skill_protocol::LeafRun run = it->second.run;
  for (auto t : it->second.timers) ctx_.loop.cancel(t);
  active_.erase(it);
  // In the receipt trace as kind kEventKindBase + the event's kind, stamped just before it is written.
  if (!receipt_trace_path_.empty() && receipts_.size() < kReceiptCapacity) {
    const std::int64_t now = wall_ns();
    receipts_.push_back({ctx_.options.id, kEventKindBase + static_cast<int>(kind), run.task_id, run.node_id, now, now});
  }
  endpoint_->report(run, kind, code, message);  // code/message are copies: they may have lived in the erased entry
}

}  // namespace rigger::scripted
