#include "monitor_host_node.hpp"

#include <algorithm>
#include <vector>

#include "monitor_registry.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"

namespace rigger::monitor {

using skill_protocol::EventKind;

SettingsTable<MonitorHostSettings> monitor_host_settings(const std::string& service_id) {
  using S = MonitorHostSettings;
  return {
      setting<S>("max_monitors", 10000u, {1u, 100000u}, &S::max_monitors, "STARTs beyond it fail with `CAPACITY`"),
      setting<S>("wrench_topic", std::string(protocol::robot::kWrench.name), &S::wrench_topic,
                 "the topic of the wrench samples the monitors are fed"),
      setting<S>("executor_id", RuntimeDefault<std::string>{[service_id] { return service_id; }, "--id"},
                 &S::executor_id, "the executor id the controller addresses; default: the service's id (`--id`)"),
  };
}

MonitorHostNode::MonitorHostNode(service::ServiceContext& ctx, const MonitorHostSettings& settings)
    : ctx_(ctx),
      max_monitors_(settings.max_monitors),
      wrench_(ctx.participant, settings.wrench_topic, dds::qos::sensor_stream()) {
  const std::string& executor_id = settings.executor_id;
  ctx.loop.on_data(wrench_, [this] { on_wrench(); });
  endpoint_ = std::make_unique<skill_protocol::ExecutorEndpoint>(
      ctx.participant, ctx.loop, ctx.log, executor_id, monitor_library_json(),
      skill_protocol::ExecutorEndpoint::Handlers{[this](const skill_protocol::StartRequest& r) { on_start(r); },
                                                 [this](const skill_protocol::ShutdownRequest& r) { on_shutdown(r); }});
  ctx.log->info("monitor host executor_id={} monitors={}", executor_id, monitor_names().size());
}

MonitorHostNode::~MonitorHostNode() {
  endpoint_.reset();  // no more commands
  for (auto& [key, active] : active_)
    if (active.timer != 0) ctx_.loop.cancel(active.timer);
}

void MonitorHostNode::on_start(const skill_protocol::StartRequest& request) {
  const RunKey key{request.run.task_id, request.run.node_id};
  if (active_.size() >= max_monitors_) {
    endpoint_->report(request.run, EventKind::kFailure, "CAPACITY",
                      "this monitor host already runs " + std::to_string(active_.size()) + " monitors (max_monitors)");
    return;
  }
  auto monitor = make_monitor(request.skill);
  if (!monitor) {  // the endpoint only passes names of the library, so this is a programming error
    endpoint_->report(request.run, EventKind::kFailure, "UNKNOWN_SKILL", "no monitor named " + request.skill);
    return;
  }
  const ParamCheck check = monitor->reset(request.params, std::chrono::system_clock::now());
  if (!check.ok()) {
    ctx_.log->warn("monitor refused node={} monitor={}: {}", request.run.node_id, request.skill, check.message());
    endpoint_->report(request.run, EventKind::kFailure, "BAD_PARAMS", check.message());
    return;
  }
  auto [it, inserted] = active_.insert_or_assign(key, Active{request.run, request.skill, std::move(monitor), 0, {}});
  (void)inserted;
  ctx_.log->debug("monitor armed node={} monitor={} active={}", request.run.node_id, request.skill, active_.size());
  // A timer with a zero duration (or an already overdue staleness) fires at once.
  on_timer(key);
  (void)it;
}

void MonitorHostNode::on_shutdown(const skill_protocol::ShutdownRequest& request) {
  const RunKey key{request.run.task_id, request.run.node_id};
  if (active_.count(key) == 0) return;
  forget(key);
  endpoint_->report(request.run, EventKind::kStopped, "", "monitor disarmed: " + request.reason);
}

void MonitorHostNode::on_wrench() {
  std::vector<RunKey> fired;
  std::vector<std::pair<RunKey, Verdict>> verdicts;
  wrench_.take([&](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
    const Stamp stamp = dds::to_domain(w.header.stamp);
    const Eigen::Vector3d force_n = dds::to_domain(w.wrench.force);
    const Eigen::Vector3d torque_nm = dds::to_domain(w.wrench.torque);
    for (auto& [key, active] : active_) {
      if (active.monitor->fired()) continue;  // already reported below
      Verdict v = active.monitor->on_wrench(stamp, force_n, torque_nm);
      if (v.fired()) verdicts.emplace_back(key, std::move(v));
    }
  });
  for (const auto& [key, verdict] : verdicts) fire(key, verdict);
}

void MonitorHostNode::fire(const RunKey& key, const Verdict& verdict) {
  auto it = active_.find(key);
  if (it == active_.end()) return;
  const skill_protocol::LeafRun run = it->second.run;
  ctx_.log->info("monitor fired node={} monitor={} code={} value={}: {}", run.node_id, it->second.name, verdict.code,
                 verdict.value, verdict.message);
  forget(key);
  endpoint_->report(run, EventKind::kFailure, verdict.code, verdict.message);
}

void MonitorHostNode::schedule(const RunKey& key, Active& active) {
  const auto deadline = active.monitor->next_deadline();
  if (!deadline) return;
  // Samples only move deadlines later, so a pending timer that is due no later than the deadline is
  // kept: when it fires, on_time finds nothing and the timer is set again for the new deadline. That
  // costs one wake-up per staleness period instead of a timer update per sample.
  if (active.timer != 0 && active.timer_deadline && *active.timer_deadline <= *deadline) return;
  if (active.timer != 0) ctx_.loop.cancel(active.timer);
  const auto delay = std::max(std::chrono::nanoseconds(0),
                              std::chrono::duration_cast<std::chrono::nanoseconds>(*deadline - std::chrono::system_clock::now()));
  active.timer_deadline = deadline;
  active.timer = ctx_.loop.after(delay, [this, key] {
    auto it = active_.find(key);
    if (it == active_.end()) return;
    it->second.timer = 0;
    it->second.timer_deadline.reset();
    on_timer(key);
  });
}

void MonitorHostNode::on_timer(const RunKey& key) {
  auto it = active_.find(key);
  if (it == active_.end()) return;
  Verdict v = it->second.monitor->on_time(std::chrono::system_clock::now());
  if (v.fired()) {
    fire(key, v);
    return;
  }
  schedule(key, it->second);
}

void MonitorHostNode::forget(const RunKey& key) {
  auto it = active_.find(key);
  if (it == active_.end()) return;
  if (it->second.timer != 0) ctx_.loop.cancel(it->second.timer);
  active_.erase(it);
}

}  // namespace rigger::monitor
