#include "task_controller_node.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "rigger/dds/conversions.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::task_controller {
namespace {

/// Offers the command writer's liveliness lease to run_service, which asserts the participant's
/// liveliness every third of it when it is the shortest (a 100 ms lease: every 33 ms).
std::chrono::milliseconds offered(service::ServiceContext& ctx, std::chrono::milliseconds lease) {
  ctx.offer_liveliness_lease(lease);
  return lease;
}

}  // namespace

TaskControllerNode::TaskControllerNode(service::ServiceContext& ctx, const std::string& journal_path)
    : ctx_(ctx),
      settings_(read_settings(ctx.config, journal_path)),
      journal_(settings_.journal_path, settings_.journal_sync),
      announcements_(ctx.participant, protocol::skill::kExecutors, dds::qos::state()),
      // Executors watch the command writer's liveliness: a controller that dies or hangs has its running
      // skills shut down by their executors within the lease (no orphaned motion).
      endpoint_(ctx.participant, offered(ctx, settings_.command_lease)),
      recipes_(ctx.participant, protocol::task::kRecipe),
      task_commands_(ctx.participant, protocol::task::kCommand),
      status_(ctx.participant),
      journal_server_(ctx.participant, journal_),
      prompts_(ctx.participant),
      responses_(ctx.participant, protocol::operator_ui::kResponse),
      safe_stops_(ctx.participant) {
  if (!settings_.stage_trace_path.empty()) {
    trace_ = std::make_unique<StageTrace>();
    StageTrace* trace = trace_.get();
    endpoint_.trace_writes([trace] { trace->command_writing(); }, [trace] { trace->command_written(); });
  }
  writer_ = std::make_unique<SideEffectWriter>(journal_, status_, ctx.log, trace_ != nullptr);
  world_ = std::make_unique<world_client::WorldClient>(ctx.participant, ctx.loop, ctx.log,
                                                       "task_controller-" + ctx.options.id);
  if (trace_) trace_loop(ctx.loop);

  ctx.loop.on_data(announcements_, [this] { on_announcements(); });
  // A lease expiry also shows as a NOT_ALIVE instance, but waking on the status makes sure we look.
  ctx.loop.on_status(announcements_.handle(), DDS_LIVELINESS_CHANGED_STATUS, [this] { on_announcements(); });
  // An executor's command reader, discovered after its announcement: the STARTs held for it go now.
  ctx.loop.on_status(endpoint_.default_writer(), DDS_PUBLICATION_MATCHED_STATUS, [this] { start_held(); });
  ctx.loop.on_data_now(endpoint_.events(), [this] { on_events(); });
  ctx.loop.on_data(recipes_, [this] { on_recipes(); });
  ctx.loop.on_data(task_commands_, [this] { on_task_commands(); });
  ctx.loop.on_data(journal_server_.queries(), [this] {
    flush_side_effects();  // a query sees every row queued so far
    journal_server_.take();
  });
  ctx.loop.on_data(responses_, [this] { on_operator_responses(); });
  report_interrupted();
  on_announcements();
}

TaskControllerNode::~TaskControllerNode() {
  // Leave nothing moving: shut every running task down. The executors stop their skills on SHUTDOWN;
  // the journal keeps the tasks unfinished, so the next start reports them INTERRUPTED.
  for (auto& [id, task] : tasks_) {
    if (!task->done()) task->engine().cancel("task controller stopping");
  }
  tasks_.clear();
  for (auto& [id, p] : pending_) ctx_.loop.cancel(p.timer);
  flush_side_effects();
  if (trace_) write_stage_trace();
}

// --- TaskHost ---

Task* TaskControllerNode::find_task(const std::string& id) {
  auto it = tasks_.find(id);
  return it == tasks_.end() ? nullptr : it->second.get();
}

void TaskControllerNode::journal(const JournalRecord& record) {
  post_flush_if_idle();
  journal_backlog_.push_back(record);
}

void TaskControllerNode::node_status(NodeStatusRow row) {
  post_flush_if_idle();
  status_backlog_.push_back(std::move(row));
}

void TaskControllerNode::is_localized(const std::string& object, double max_age_s,
                                      std::function<void(const world_client::Reply&)> answer) {
  world_->is_localized(object, max_age_s, settings_.condition_timeout, std::move(answer));
}

void TaskControllerNode::localized(const std::string& task_id, const std::string& node_id, const std::string& object) {
  // The pose the rest of the task relies on, for a resume after a crash (relocalization.hpp). Read after
  // the leaf's SUCCESS: a Localize has stored its pose by then.
  world_->pose(object, kRecheckFrame, settings_.condition_timeout,
               [this, task_id, node_id, object](const world_client::Reply& r) {
                 if (!r.ok) {
                   journal({wall_now_s(), task_id, node_id, kWorldRow, kPoseUnknownCode,
                            object + ": " + r.code + (r.message.empty() ? "" : ": " + r.message)});
                   return;
                 }
                 LocalizedPose p;
                 p.object = object;
                 p.pose_world_object = r.pose;
                 p.stamp_s = wall_now_s() - r.age_s;
                 journal({wall_now_s(), task_id, node_id, kWorldRow, kLocalizedCode, localized_pose_row(p)});
               });
}

std::string TaskControllerNode::holder_of(const std::vector<std::string>& resources, const std::string& task_id,
                                          const std::set<std::string>* started, const std::string& node_id) const {
  const auto holder = executors_.holder(resources, task_id, started, node_id);
  return holder ? holder->describe() : std::string();
}

bool TaskControllerNode::safe_stop(const std::string& resource, const std::string& reason) {
  return safe_stops_.command(resource, true, ctx_.options.id, reason) == DDS_RETCODE_OK;
}

void TaskControllerNode::task_finished(const std::string& id, int state, const std::string& journal_state,
                                       const bt::TaskResult& result, const std::string& message) {
  flush_side_effects();  // the task's row comes after its timeline
  if (!journal_.finish_task(id, journal_state, result.code, message, wall_now_s()))
    ctx_.log->error("journal write failed task={}: {}", id, journal_.last_error());
  if (!status_.task(id, state, result.code, message, result.origin))
    ctx_.log->error("task status write failed task={}", id);
  ctx_.log->info("task finished task={} outcome={} code={} origin={} message={}", id, bt::to_string(result.outcome),
                 result.code, result.origin, message);
  ctx_.loop.post([this, id] { forget_task(id); });
}

void TaskControllerNode::trace_loop(dds::EventLoop& loop) {
  // Labels are string literals: a mark costs a clock read and a push_back into reserved memory.
  using D = dds::EventLoop::Dispatch;
  const dds_entity_t events = endpoint_.events().handle(), announcements = announcements_.handle();
  loop.observe_dispatch([trace = trace_.get(), events, announcements](D what, dds_entity_t entity, bool begin) {
    const char phase = begin ? 'b' : 'e';
    const bool ours = entity == events;
    switch (what) {
      case D::kWoke:
        return trace->mark("woke", '.');
      case D::kListener:
        return trace->mark(ours ? "listener events" : "listener other", phase);
      case D::kPending:
        return trace->mark(ours ? "pending events" : "pending other", phase);
      case D::kData:
        return trace->mark(entity == announcements ? "announcements" : "data other", phase);
      case D::kStatus:
        return trace->mark(entity == announcements ? "announcement status" : "status other", phase);
      case D::kTimer:
        return trace->mark("timer", phase);
      case D::kPosted:
        return trace->mark("posted", phase);
    }
  });
}

void TaskControllerNode::post_flush_if_idle() {
  // The first queued item schedules the hand-over; later ones ride along with it.
  if (flush_pending_) return;
  flush_pending_ = true;
  if (settings_.flush_delay.count() == 0) {
    ctx_.loop.post([this] { hand_over_side_effects(); });
    return;
  }
  flush_timer_ = ctx_.loop.after(settings_.flush_delay, [this] {
    flush_timer_ = 0;
    hand_over_side_effects();
  });
}

void TaskControllerNode::hand_over_side_effects() {
  if (flush_timer_ != 0) ctx_.loop.cancel(flush_timer_);
  flush_timer_ = 0;
  flush_pending_ = false;
  if (journal_backlog_.empty() && status_backlog_.empty()) return;
  if (trace_) traced_upto_.push_back(trace_->records().size());
  writer_->hand_over(std::exchange(journal_backlog_, {}), std::exchange(status_backlog_, {}));
}

void TaskControllerNode::flush_side_effects() {
  hand_over_side_effects();
  writer_->drain();
}

void TaskControllerNode::write_stage_trace() {
  // Each batch's write, done on the writer's thread, enters the trace now: its records flushed when it
  // ended, and a "flush" span among the loop's marks.
  const std::vector<SideEffectWriter::Times> times = writer_->times();
  for (std::size_t i = 0; i < times.size() && i < traced_upto_.size(); ++i) {
    trace_->flushed_upto(traced_upto_[i], times[i].ended_ns);
    trace_->mark_at(times[i].began_ns, "flush", 'b');
    trace_->mark_at(times[i].ended_ns, "flush", 'e');
  }
  if (!trace_->write(settings_.stage_trace_path))
    ctx_.log->error("stage trace not written path={}", settings_.stage_trace_path);
}

// --- executors ---

void TaskControllerNode::on_announcements() {
  std::vector<std::string> lost;
  bool appeared = false;
  announcements_.take(
      [&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t& info) {
        const std::string id = dds::to_string(a.executor_id);
        const auto change =
            executors_.announce(id, info.instance_state == DDS_IST_ALIVE, dds::to_string(a.library_json),
                                dds::to_string_vector(a.skills), skill_protocol::runs_of(a));
        if (change.lost) lost.push_back(id);
        if (change.came_up) ctx_.log->info("executor up executor={}", id);
        if (change.alive) {
          // Its participant, whose reader the writer of its command partition must match.
          if (dds_builtintopic_endpoint_t* w =
                  dds_get_matched_publication_data(announcements_.handle(), info.publication_handle)) {
            endpoint_.executor_seen(id, w->participant_key, change.came_up);
            dds_builtintopic_free_endpoint(w);
          }
        }
        if (!change.library_error.empty())
          ctx_.log->warn("executor library unreadable executor={}: {}", id, change.library_error);
        appeared = appeared || change.alive;
      },
      [&](const rigger_skill_ExecutorAnnouncement& key, const dds_sample_info_t& info) {
        if (info.instance_state == DDS_IST_ALIVE) return;
        const std::string id = dds::to_string(key.executor_id);
        if (executors_.gone(id)) lost.push_back(id);
      });
  for (const auto& id : lost) executor_lost(id);
  if (appeared) retry_pending();
  start_held();  // as soon as an announcement shows their resources free
}

void TaskControllerNode::start_held() {
  std::vector<std::string> holding;
  for (const auto& [id, task] : tasks_)
    if (task->holds_starts()) holding.push_back(id);
  for (const auto& id : holding)
    if (Task* task = find_task(id)) task->start_held();
}

void TaskControllerNode::wait_for_executors(const std::string& task_id, std::function<void(bool may_wait)> again) {
  auto& p = pending_[task_id];
  p.again = std::move(again);
  p.timer = ctx_.loop.after(settings_.executor_wait, [this, task_id] {
    auto it = pending_.find(task_id);
    if (it == pending_.end()) return;
    const auto decide = std::move(it->second.again);
    pending_.erase(it);
    decide(false);
  });
}

void TaskControllerNode::retry_pending() {
  std::vector<std::string> ids;
  for (const auto& [id, p] : pending_) ids.push_back(id);
  for (const auto& id : ids) {
    auto it = pending_.find(id);
    if (it == pending_.end()) continue;
    const auto decide = std::move(it->second.again);
    ctx_.loop.cancel(it->second.timer);
    pending_.erase(it);
    decide(true);
  }
}

void TaskControllerNode::executor_lost(const std::string& executor_id) {
  ctx_.log->warn("executor lost executor={}", executor_id);
  std::vector<std::string> task_ids;
  for (const auto& [id, task] : tasks_) task_ids.push_back(id);
  for (const auto& task_id : task_ids)
    if (Task* task = find_task(task_id)) task->executor_lost(executor_id);
}

// --- recipes ---

void TaskControllerNode::reject(const std::string& task_id, RejectCode code, const std::string& message,
                                const std::vector<recipe::Error>& errors) {
  ctx_.log->warn("recipe rejected task={} code={} errors={} message={}", task_id, to_string(code), errors.size(),
                 message);
  if (!status_.task(task_id, rigger_task_TASK_REJECTED, to_string(code), message, "", errors))
    ctx_.log->error("task status write failed task={}", task_id);
}

void TaskControllerNode::on_recipes() {
  recipes_.take([this](const rigger_task_Recipe& r, const dds_sample_info_t&) {
    const std::string task_id = dds::to_string(r.task_id);
    // Whatever is in the text, a failure here must never take the controller down.
    try {
      handle_recipe(task_id, r.recipe_json ? std::string(r.recipe_json) : std::string(), true);
    } catch (const std::exception& e) {
      reject(task_id, RejectCode::kInvalidRecipe, std::string("recipe could not be handled: ") + e.what());
    }
  });
}

void TaskControllerNode::handle_recipe(const std::string& task_id, const std::string& text, bool may_wait) {
  AdmissionRequest request;
  request.task_id = task_id;
  request.text = text;
  request.id_used =
      tasks_.count(task_id) || pending_.count(task_id) || (!task_id.empty() && journal_.has_task(task_id));
  request.may_wait = may_wait && settings_.executor_wait.count() > 0;
  for (const auto& [id, task] : tasks_)
    if (!task->done()) request.running.push_back({id, &task->resources()});
  std::vector<std::string> problems;
  const recipe::RecipeValidator validator(executors_.live_library(&problems), settings_.validator);
  for (const auto& p : problems) ctx_.log->warn("{}", p);
  Admission admission = admit(request, validator);
  if (admission.outcome == Admission::Outcome::kWait) {
    // Perhaps its executor has not been discovered yet: wait for announcements, then decide.
    ctx_.log->info("recipe waits for executors task={} first={}", task_id, admission.message);
    wait_for_executors(task_id, [this, task_id, text](bool wait) { handle_recipe(task_id, text, wait); });
    return;
  }
  if (admission.outcome == Admission::Outcome::kRejected) {
    reject(task_id, admission.code, admission.message, admission.errors);
    return;
  }
  // Journal before acting: a crash from here on leaves the task unfinished in the journal.
  flush_side_effects();  // the journal in the order things happened
  if (!journal_.add_task(task_id, text, wall_now_s())) {
    reject(task_id, RejectCode::kJournalError, "journal write failed: " + journal_.last_error());
    return;
  }
  std::unique_ptr<Task> task;
  try {
    task = std::make_unique<Task>(static_cast<TaskHost&>(*this), std::move(*admission.recipe), task_id);
  } catch (const bt::SpecError& e) {
    journal_.finish_task(task_id, "FAILED", to_string(RejectCode::kInvalidRecipe), e.what(), wall_now_s());
    reject(task_id, RejectCode::kInvalidRecipe, e.what());
    return;
  }
  status_.task(task_id, rigger_task_TASK_ACCEPTED, "", "", "");
  ctx_.log->info("task accepted task={} nodes={}", task_id, task->engine().spec().nodes.size());
  task->set_localizing(localizing_leaves(task->engine().spec(), validator.library()));
  Task& t = *task;
  tasks_[task_id] = std::move(task);
  status_.task(task_id, rigger_task_TASK_RUNNING, "", "", "");
  t.log_result("start", "root", t.engine().start());
}

void TaskControllerNode::forget_task(const std::string& task_id) {
  auto it = tasks_.find(task_id);
  if (it != tasks_.end() && it->second->done()) tasks_.erase(it);
}

// --- executor events, task commands, operator answers ---

void TaskControllerNode::on_events() {
  if (trace_) trace_->woke();
  endpoint_.take(
      [this](const ReceivedEvent& e) {
        if (trace_)
          trace_->begin(e.executor_id, std::string(bt::to_string(to_leaf_event(e.outcome).kind)), e.stamp_wall_ns);
        Task* task = find_task(e.task_id);
        if (task == nullptr) {
          ctx_.log->warn("event rejected (unknown task) executor={} task={} node={}", e.executor_id, e.task_id,
                         e.node_id);
        } else {
          task->on_event(e);
        }
        if (trace_) trace_->engine_done();
      },
      [this](const ReceivedEvent& e, std::uint64_t last) {
        ctx_.log->warn("event rejected (duplicate or out of order) executor={} task={} node={} seq={} last={}",
                       e.executor_id, e.task_id, e.node_id, e.seq, last);
        journal({wall_now_s(), e.task_id, e.node_id, "REJECTED_EVENT", "OUT_OF_ORDER",
                 "from " + e.executor_id + " seq " + std::to_string(e.seq) + " after " + std::to_string(last)});
      });
}

void TaskControllerNode::on_task_commands() {
  task_commands_.take([this](const rigger_task_TaskCommand& c, const dds_sample_info_t&) {
    const std::string task_id = dds::to_string(c.task_id);
    const std::string reason =
        dds::to_string(c.reason).empty() ? "requested by " + dds::to_string(c.issuer) : dds::to_string(c.reason);
    Task* task = find_task(task_id);
    if (task == nullptr && c.kind == rigger_task_TASK_RESUME) {
      resume_interrupted(task_id, dds::to_string(c.issuer), reason);
      return;
    }
    if (task == nullptr && c.kind == rigger_task_TASK_CANCEL && cancel_resuming(task_id, reason)) return;
    if (task == nullptr || task->done()) {
      ctx_.log->warn("task command for a task not running task={} kind={}", task_id, static_cast<int>(c.kind));
      return;
    }
    const int state = task->command(c.kind, reason, dds::to_string(c.issuer));
    if (state >= 0) status_.task(task_id, state, "", reason, "");
  });
}

void TaskControllerNode::on_operator_responses() {
  responses_.take([this](const rigger_operator_ui_OperatorResponse& wire, const dds_sample_info_t&) {
    const operator_protocol::Response response = operator_protocol::from_wire(wire);
    const std::string& prompt_id = response.prompt_id;
    const std::string& answer = response.answer;
    const std::string& by = response.operator_id;
    const auto id = PromptId::parse(prompt_id);
    if (!id) {
      ctx_.log->warn("operator answer rejected: prompt id {} is not one of ours", prompt_id);
      return;
    }
    if (auto r = resuming_.find(id->task_id); r != resuming_.end() && r->second.prompt == *id) {
      answer_resume(*id, answer, by);
      return;
    }
    Task* task = find_task(id->task_id);
    if (task == nullptr || !task->prompt_open(*id)) {
      // Answered, withdrawn (the task was canceled or its branch shut down) or never asked.
      ctx_.log->warn("operator answer rejected: prompt {} is not open answer={} by={}", prompt_id, answer, by);
      if (journal_.has_task(id->task_id))
        journal({wall_now_s(), id->task_id, id->node_id, "REJECTED_EVENT", "NOT_ASKED",
                 "answer \"" + answer + "\" by " + by + " to prompt " + prompt_id +
                     ", which is not open (answered, withdrawn or task ended)"});
      return;
    }
    task->answer(*id, answer, by);
  });
}

}  // namespace rigger::task_controller
