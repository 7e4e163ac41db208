#include "executor_node.hpp"

#include <unistd.h>

#include <stdexcept>

namespace rigger::skill_sdk {

using skill_protocol::EventKind;

std::vector<std::string> configured_skills(const Config& config, const SkillRegistry& registry) {
  if (!config.has("skills")) return registry.names();
  const auto names = config.get<std::vector<std::string>>("skills");
  if (names.empty()) config.fail("skills", "expected at least one skill name");
  for (const auto& name : names) {
    if (!registry.find(name)) {
      std::string known;
      for (const auto& n : registry.names()) known += (known.empty() ? "" : ", ") + n;
      config.fail("skills", "unknown skill '" + name + "'; this binary has: " + known);
    }
  }
  return names;
}

SkillExecutorNode::SkillExecutorNode(dds::ServiceContext& ctx, SkillRegistry registry)
    : ctx_(ctx), registry_(std::move(registry)), timers_(ctx.loop) {
  const std::string executor_id = ctx.config.get<std::string>("executor_id", ctx.options.id);
  const auto skills = configured_skills(ctx.config, registry_);
  if (ctx.config.get<bool>("robot", true)) robot_ = std::make_unique<DdsRobot>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (ctx.config.get<bool>("gripper", true))
    gripper_ = std::make_unique<DdsGripper>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (ctx.config.get<bool>("world_model", true)) {
    world_client_ = std::make_unique<world_client::WorldClient>(ctx.participant, ctx.loop, ctx.log,
                                                                executor_id + "-" + std::to_string(::getpid()));
    resolver_ = std::make_unique<WorldFeatureResolver>(*world_client_);
    world_access_ = std::make_unique<DdsWorldAccess>(*world_client_);
  }
  if (ctx.config.get<bool>("crane", true))
    crane_ = std::make_unique<DdsCraneMonitor>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (ctx.config.get<bool>("tracker", true))
    tracker_ = std::make_unique<DdsVisionTracker>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (ctx.config.get<bool>("admittance", true))
    admittance_ = std::make_unique<DdsAdmittanceController>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (ctx.config.get<bool>("operator", true))
    operator_panel_ = std::make_unique<DdsOperatorPanel>(ctx.participant, ctx.loop, ctx.log, executor_id);
  run_options_.resolve_frame = ctx.config.get<std::string>("resolve_frame", "world");
  run_options_.resolve_timeout = from_seconds(ctx.config.get_in_range("resolve_timeout_s", 2.0, 0.05, 30.0));
  ctx.config.finish();
  devices_ = Devices{robot_.get(), gripper_.get(), resolver_.get()};
  devices_.crane = crane_.get();
  devices_.tracker = tracker_.get();
  devices_.admittance = admittance_.get();
  devices_.operator_panel = operator_panel_.get();
  devices_.world_access = world_access_.get();
  endpoint_ = std::make_unique<skill_protocol::ExecutorEndpoint>(
      ctx.participant, ctx.loop, ctx.log, executor_id, registry_.library_json(skills),
      skill_protocol::ExecutorEndpoint::Handlers{
          [this](const skill_protocol::StartRequest& r) { on_start(r); },
          [this](const skill_protocol::ShutdownRequest& r) { on_shutdown(r); },
          [this](const skill_protocol::PauseRequest& r) { return on_pause(r); }});
  std::string list;
  for (const auto& s : skills) list += (list.empty() ? "" : ",") + s;
  ctx.log->info("skill executor executor_id={} skills={}", executor_id, list);
}

SkillExecutorNode::~SkillExecutorNode() {
  // The service is stopping: command every running skill's safe stop (e.g. MOTION_STOP is written at
  // once). The event loop has already stopped, so confirmations cannot be awaited here; a skill whose
  // safe stop needs them is logged. (EventLoop has no way to run again after stop().)
  for (auto& [key, run] : runs_) {
    if (run->finished()) continue;
    run->shutdown("executor stopping");
    if (!run->finished())
      ctx_.log->warn("executor stopping: node {} commanded its safe stop, unconfirmed", key.second);
  }
  endpoint_.reset();
  runs_.clear();
}

void SkillExecutorNode::on_start(const skill_protocol::StartRequest& request) {
  const SkillType* type = registry_.find(request.skill);
  if (!type) {  // the endpoint checks names against the announced library; this is a safety net
    endpoint_->report(request.run, EventKind::kFailure, "UNKNOWN_SKILL", "no skill named " + request.skill);
    return;
  }
  const RunKey key{request.run.task_id, request.run.node_id};
  const skill_protocol::LeafRun leaf = request.run;
  SkillRun::Callbacks callbacks;
  callbacks.progress = [this, leaf](double fraction, const std::string& message) {
    endpoint_->report(leaf, EventKind::kProgress, "", message, fraction);
  };
  callbacks.finished = [this, leaf, key](const SkillResult& result) {
    const EventKind kind = result.kind == SkillResult::Kind::kSuccess   ? EventKind::kSuccess
                           : result.kind == SkillResult::Kind::kStopped ? EventKind::kStopped
                                                                        : EventKind::kFailure;
    endpoint_->report(leaf, kind, result.code, result.message);
    // The run calls this from inside itself: destroy it after the current handler.
    ctx_.loop.post([this, key, seq = leaf.start_seq] {
      auto it = runs_.find(key);
      if (it != runs_.end() && it->second->finished()) runs_.erase(it);
      (void)seq;
    });
  };
  auto run = std::make_unique<SkillRun>(*type, request.params, devices_, timers_, ctx_.log, std::move(callbacks), run_options_);
  SkillRun* raw = run.get();
  runs_[key] = std::move(run);
  ctx_.log->info("skill start node={} skill={}", request.run.node_id, request.skill);
  raw->start();
}

void SkillExecutorNode::on_shutdown(const skill_protocol::ShutdownRequest& request) {
  auto it = runs_.find({request.run.task_id, request.run.node_id});
  if (it == runs_.end() || it->second->finished()) return;  // the endpoint answered NOT_RUNNING or the end is reported
  it->second->shutdown(request.reason);
}

skill_protocol::PauseAnswer SkillExecutorNode::on_pause(const skill_protocol::PauseRequest& request) {
  auto it = runs_.find({request.run.task_id, request.run.node_id});
  if (it == runs_.end() || it->second->finished()) return {"NOT_RUNNING", "the run has ended"};
  const Skill* skill = it->second->skill();
  const std::string state = skill ? " in state " + skill->state() : std::string(" before its first state");
  if (!it->second->pause(request.pause))
    return {request.pause ? "ALREADY_PAUSED" : "NOT_PAUSED", "the skill did not change" + state};
  ctx_.log->info("skill {} node={} reason={}{}", request.pause ? "paused" : "resumed", request.run.node_id,
                 request.reason, state);
  return {"", request.pause ? "holds still" + state : "continues" + state};
}

}  // namespace rigger::skill_sdk
