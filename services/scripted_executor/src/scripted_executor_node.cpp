#include "scripted_executor_node.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"
#include "rigger/base/install.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"

namespace rigger::scripted {
namespace {

nlohmann::json load_library(const Config& config) {
  const std::filesystem::path path = config_path(config, "library_file", "test/data/scripted_skill_library.json");
  auto parsed = parse_json_file_bounded(path);
  if (!parsed.ok()) config.fail("library_file", parsed.error->to_string());
  return std::move(parsed.value);
}

/// The receipt trace holds at most this many commands (a benchmark's thousands of trials fit).
constexpr std::size_t kReceiptCapacity = 1U << 16;

}  // namespace

ScriptedExecutorNode::ScriptedExecutorNode(dds::ServiceContext& ctx) : ctx_(ctx) {
  nlohmann::json library = load_library(ctx.config);
  if (!library.contains("skills") || !library["skills"].is_array())
    ctx.config.fail("library_file", "expected a skill library with a \"skills\" array");
  std::set<std::string> wanted;
  if (ctx.config.has("skills"))
    for (const auto& s : ctx.config.get<std::vector<std::string>>("skills")) wanted.insert(s);
  nlohmann::json skills = nlohmann::json::array();
  std::set<std::string> missing = wanted;  // `wanted` itself must stay whole: it filters every description
  for (const auto& d : library["skills"]) {
    const std::string name = d.value("name", "");
    if (!wanted.empty() && !wanted.count(name)) continue;
    is_monitor_[name] = d.value("kind", "skill") == "monitor";
    missing.erase(name);
    skills.push_back(d);
  }
  if (!missing.empty()) ctx.config.fail("skills", "not in the library: " + *missing.begin());
  library["skills"] = skills;

  default_monitor_.mode = Mode::kRun;
  default_skill_ = parse_behaviour(ctx.config.child_or_empty("default"), default_skill_);
  if (ctx.config.has("behaviours")) {
    const auto& raw = ctx.config.raw("behaviours");
    if (!raw.is_object()) ctx.config.fail("behaviours", "expected an object: skill name → behaviour");
    auto children = ctx.config.child("behaviours");
    for (const auto& [name, value] : raw.items()) {
      auto m = is_monitor_.find(name);
      if (m == is_monitor_.end()) children.fail(name, "not an announced skill or monitor");
      by_skill_[name] = parse_behaviour(children.child(name), m->second ? default_monitor_ : default_skill_);
    }
  }
  if (ctx.config.has("nodes")) {
    const auto& raw = ctx.config.raw("nodes");
    if (!raw.is_object()) ctx.config.fail("nodes", "expected an object: node id → behaviour");
    auto children = ctx.config.child("nodes");
    for (const auto& [node_id, value] : raw.items()) by_node_[node_id] = parse_behaviour(children.child(node_id), default_skill_);
  }
  receipt_trace_path_ = ctx.config.get<std::string>("receipt_trace_path", "");
  ctx.config.finish();

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
  ctx.log->info("scripted executor ready skills={}", skills.size());
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
  endpoint_->report(run, kind, code, message);  // code/message are copies: they may have lived in the erased entry
}

}  // namespace rigger::scripted
