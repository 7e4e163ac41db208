#include "executor_node.hpp"

#include <unistd.h>

#include <algorithm>
#include <stdexcept>

namespace rigger::skill_sdk {

using skill_protocol::EventKind;

SettingsTable<ExecutorSettings> executor_settings(const std::string& service_id, const SkillRegistry& registry) {
  using S = ExecutorSettings;
  const std::vector<std::string> known = registry.names();
  return {
      setting<S>("executor_id", RuntimeDefault<std::string>{[service_id] { return service_id; }, "--id"},
                 &S::executor_id, "the executor id the controller addresses; default: the service's id (`--id`)"),
      setting<S>(
          "skills", RuntimeDefault<std::vector<std::string>>{[known] { return known; }, "every skill built in"},
          [known](S& s, const std::vector<std::string>& names, const Config& config) {
            if (names.empty()) config.fail("skills", "expected at least one skill name");
            for (const auto& name : names) {
              if (std::find(known.begin(), known.end(), name) != known.end()) continue;
              std::string list;
              for (const auto& n : known) list += (list.empty() ? "" : ", ") + n;
              config.fail("skills", "unknown skill '" + name + "'; this binary has: " + list);
            }
            s.skills = names;
          },
          "the skills announced (their library: `--describe`)"),
      setting<S>("robot", true, &S::robot, "offer the robot (cmd_motion, motion_status, state) to skills"),
      setting<S>("gripper", true, &S::gripper, "offer the gripper (gripper/cmd, gripper/state)"),
      setting<S>("world_model", true, &S::world_model,
                 "resolve feature_ref params through the world model, and offer its features and pose updates "
                 "(Localize, Screw, InsertVisuallyGuided) and cell revisions (CalibrateCamera)"),
      setting<S>("crane", true, &S::crane,
                 "offer the crane's health and external control (crane/state, crane/control)"),
      setting<S>("tracker", true, &S::tracker, "offer the vision tracker (tracker/command, tracker/pose)"),
      setting<S>("admittance", true, &S::admittance, "offer admittance control (admittance/command, admittance/state)"),
      setting<S>("operator", true, &S::operator_panel, "offer operator prompts (operator/prompt, operator/response)"),
      setting<S>("resolve_frame", "world", &S::resolve_frame, "the frame feature_ref params are resolved in"),
      setting<S>("resolve_timeout_s", 2.0, {0.05, 30.0}, &S::resolve_timeout,
                 "how long resolving a feature_ref param may take"),
  };
}

SkillExecutorNode::SkillExecutorNode(service::ServiceContext& ctx, SkillRegistry registry)
    : ctx_(ctx), registry_(std::move(registry)), timers_(ctx.loop) {
  const ExecutorSettings settings = read_settings(ctx.config, executor_settings(ctx.options.id, registry_));
  const std::string& executor_id = settings.executor_id;
  const auto& skills = settings.skills;
  if (settings.robot) robot_ = std::make_unique<DdsRobot>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (settings.gripper) gripper_ = std::make_unique<DdsGripper>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (settings.world_model) {
    const std::string client_id = executor_id + "-" + std::to_string(::getpid());
    world_client_ = std::make_unique<world_client::WorldClient>(ctx.participant, ctx.loop, ctx.log, client_id);
    resolver_ = std::make_unique<WorldFeatureResolver>(*world_client_);
    world_access_ = std::make_unique<DdsWorldAccess>(*world_client_, ctx.participant, ctx.loop, ctx.log, client_id);
  }
  if (settings.crane) crane_ = std::make_unique<DdsCraneMonitor>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (settings.tracker) tracker_ = std::make_unique<DdsVisionTracker>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (settings.admittance)
    admittance_ = std::make_unique<DdsAdmittanceController>(ctx.participant, ctx.loop, ctx.log, executor_id);
  if (settings.operator_panel)
    operator_panel_ = std::make_unique<DdsOperatorPanel>(ctx.participant, ctx.loop, ctx.log, executor_id);
  run_options_.resolve_frame = settings.resolve_frame;
  run_options_.resolve_timeout = settings.resolve_timeout;
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
