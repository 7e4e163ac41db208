#include "task_controller_node.hpp"

#include <algorithm>
#include <chrono>

#include "rigger/recipe/conditions.hpp"
#include "rigger/base/text.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/executor/executor_endpoint.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/skill/skill_library.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::task_controller {
namespace {

using bt::NodeState;

rigger_task_NodeState to_wire(NodeState s) {
  switch (s) {
    case NodeState::kIdle: return rigger_task_NODE_IDLE;
    case NodeState::kRunning: return rigger_task_NODE_RUNNING;
    case NodeState::kStopping: return rigger_task_NODE_STOPPING;
    case NodeState::kSuccess: return rigger_task_NODE_SUCCESS;
    case NodeState::kFailure: return rigger_task_NODE_FAILURE;
    case NodeState::kStopped: return rigger_task_NODE_STOPPED;
  }
  return rigger_task_NODE_IDLE;
}

/// A steady-clock instant as wall time (engine timestamps are steady; the wire carries wall time).
rigger_geometry_Time wall_of(bt::TimePoint t) {
  const auto age = bt::Clock::now() - t;
  return dds::to_wire(std::chrono::system_clock::now() -
                      std::chrono::duration_cast<std::chrono::system_clock::duration>(age));
}

std::string parent_of(const std::string& id) {
  const auto slash = id.rfind('/');
  return slash == std::string::npos ? std::string() : id.substr(0, slash);
}

bool intersects(const std::vector<std::string>& a, const std::vector<std::string>& b, std::string& common) {
  for (const auto& x : a)
    if (std::binary_search(b.begin(), b.end(), x)) {
      common = x;
      return true;
    }
  return false;
}

/// The conditions the controller answers itself (through the world model), as a skill library.
const skill::SkillLibrary& controller_conditions() {
  static const skill::SkillLibrary library = skill::SkillLibrary::from_json(recipe::controller_conditions_json());
  return library;
}

}  // namespace

/// One running task: its engine and the Port through which the engine acts on DDS.
class TaskControllerNode::Task : public bt::Port {
 public:
  struct LeafRun {
    std::string executor_id;
    std::uint64_t start_seq = 0;
    bt::Activation activation = 0;
  };

  Task(TaskControllerNode& node, recipe::ValidatedRecipe recipe, std::string id)
      : node_(node), id_(std::move(id)), resources_(recipe.resources) {
    engine_ = std::make_unique<bt::Engine>(std::move(recipe.tree), *this);
  }
  ~Task() override {
    for (const auto& [engine_timer, loop_timer] : timers_) node_.ctx_.loop.cancel(loop_timer);
  }

  const std::string& id() const { return id_; }
  bt::Engine& engine() { return *engine_; }
  const std::vector<std::string>& resources() const { return resources_; }
  bool done() const { return engine_->result().has_value(); }
  std::map<std::string, LeafRun>& runs() { return runs_; }
  /// Prompt id → (node id, activation).
  std::map<std::string, std::pair<std::string, bt::Activation>>& prompts() { return prompts_; }

  /// Runs `fn` on the engine later (outside any Port callback), if the task still exists then.
  void defer(std::function<void(Task&)> fn) {
    TaskControllerNode* node = &node_;
    std::string id = id_;
    node_.ctx_.loop.post([node, id, fn = std::move(fn)] {
      auto it = node->tasks_.find(id);
      if (it != node->tasks_.end()) fn(*it->second);
    });
  }

  void log_result(const char* what, const std::string& node_id, const bt::EventResult& r) {
    if (r.acted_on()) return;
    node_.ctx_.log->warn("{} rejected task={} node={} status={} reason={}", what, id_, node_id,
                         bt::to_string(r.status), r.reason);
    node_.journal({wall_now_s(), id_, node_id, "REJECTED_EVENT", std::string(bt::to_string(r.status)), r.reason});
  }

  // --- bt::Port ---
  bt::TimePoint now() override { return bt::Clock::now(); }

  void start_leaf(const bt::NodeSpec& spec, bt::Activation activation) override {
    const std::string executor_id = node_.pick_executor(spec.leaf, spec.executor);
    if (executor_id.empty()) {
      const std::string why = "no live executor offers " + spec.leaf +
                              (spec.executor.empty() ? std::string() : " as " + spec.executor);
      node_.journal({wall_now_s(), id_, spec.id, "COMMAND", codes::kNoExecutor, why});
      std::string node_id = spec.id;
      defer([node_id, activation, why](Task& t) {
        t.log_result("executor lost", node_id, t.engine().on_leaf_lost(node_id, activation, why));
      });
      return;
    }
    LeafRun run{executor_id, ++node_.command_seq_, activation};
    runs_[spec.id] = run;
    const std::string params = spec.params.dump();
    node_.journal({wall_now_s(), id_, spec.id, "COMMAND", "START",
                   spec.leaf + " on " + executor_id + " seq " + std::to_string(run.start_seq) + " " + params});
    send(spec, run, rigger_skill_SKILL_START, params, "");
  }

  void shutdown_leaf(const bt::NodeSpec& spec, bt::Activation activation, const std::string& reason) override {
    auto it = runs_.find(spec.id);
    if (it == runs_.end() || it->second.activation != activation) return;  // never sent: nothing to stop
    LeafRun shutdown = it->second;
    shutdown.start_seq = ++node_.command_seq_;
    node_.journal({wall_now_s(), id_, spec.id, "COMMAND", "SHUTDOWN", reason});
    send(spec, shutdown, rigger_skill_SKILL_SHUTDOWN, "{}", reason);
  }

  void evaluate_condition(const bt::NodeSpec& spec, bt::Activation activation) override {
    TaskControllerNode* node = &node_;
    const std::string task_id = id_, node_id = spec.id, leaf = spec.leaf;
    // The answer always arrives on a later loop turn (WorldClient never calls back inside the call).
    auto answer = [node, task_id, node_id, activation](bool holds, const std::string& code, const std::string& message) {
      auto it = node->tasks_.find(task_id);
      if (it == node->tasks_.end()) return;
      it->second->log_result("condition", node_id,
                             it->second->engine().on_condition_result(node_id, activation, holds, code, message));
    };
    if (leaf == "ObjectLocalized") {
      const std::string object = spec.params.value("object", std::string());
      const double max_age_s = spec.params.value("max_age_s", 5.0);
      node_.world_->is_localized(object, max_age_s, node_.condition_timeout_,
                                 [answer, object, max_age_s](const world_client::Reply& r) {
                                   const std::string what = "ObjectLocalized(" + object + ", max_age_s " +
                                                            number_text(max_age_s) + ")";
                                   if (!r.ok) {
                                     answer(false, r.code, what + ": " + r.message);
                                   } else if (r.localized) {
                                     answer(true, "", what + ": pose " + number_text(r.age_s) + " s old");
                                   } else {
                                     answer(false, r.code.empty() ? "NOT_LOCALIZED" : r.code,
                                            what + ": " + (r.message.empty() ? "not localized" : r.message));
                                   }
                                 });
      return;
    }
    defer([node_id, leaf, activation](Task& t) {
      t.log_result("condition", node_id,
                   t.engine().on_condition_result(node_id, activation, false, "UNKNOWN_CONDITION",
                                                  "the controller cannot evaluate condition " + leaf));
    });
  }

  void ask_operator(const bt::NodeSpec& spec, bt::Activation activation) override {
    const std::string prompt_id = id_ + "#" + spec.id + "#" + std::to_string(activation);
    prompts_[prompt_id] = {spec.id, activation};
    write_prompt(prompt_id, spec, true);
    node_.journal({wall_now_s(), id_, spec.id, "OPERATOR", "ASK", spec.prompt});
  }

  void withdraw_operator_request(const bt::NodeSpec& spec, bt::Activation activation) override {
    const std::string prompt_id = id_ + "#" + spec.id + "#" + std::to_string(activation);
    prompts_.erase(prompt_id);
    write_prompt(prompt_id, spec, false);
  }

  void schedule(bt::TimerId id, bt::TimePoint deadline) override {
    const auto delay = std::max(bt::Clock::duration::zero(), deadline - bt::Clock::now());
    TaskControllerNode* node = &node_;
    std::string task_id = id_;
    timers_[id] = node_.ctx_.loop.after(std::chrono::duration_cast<std::chrono::nanoseconds>(delay),
                                        [node, task_id, id] {
                                          auto it = node->tasks_.find(task_id);
                                          if (it == node->tasks_.end()) return;
                                          it->second->timers_.erase(id);
                                          it->second->engine().on_timer(id);
                                        });
  }

  void cancel_timer(bt::TimerId id) override {
    auto it = timers_.find(id);
    if (it == timers_.end()) return;
    node_.ctx_.loop.cancel(it->second);
    timers_.erase(it);
  }

  void escalate_safe_stop(const bt::NodeSpec& spec, const std::string& why) override {
    // The devices of every resource the leaf held that a safe stop can name stop and stay stopped
    // until a person resets them (riggerctl estop --reset RESOURCE); the others are logged.
    std::string resources, stopped;
    const auto& stoppable = safety::stoppable_resources();
    for (const auto& r : spec.resources) {
      resources += (resources.empty() ? "" : ",") + r;
      if (std::find(stoppable.begin(), stoppable.end(), r) == stoppable.end()) continue;
      const std::string reason = "task " + id_ + ", node " + spec.id + ": " + why;
      if (node_.safe_stops_.command(r, true, node_.ctx_.options.id, reason) != DDS_RETCODE_OK)
        node_.ctx_.log->error("safe stop write failed resource={} task={} node={}", r, id_, spec.id);
      stopped += (stopped.empty() ? "" : ",") + r;
    }
    node_.ctx_.log->error("safe stop escalated task={} node={} resources=[{}] stopped=[{}] why={}", id_, spec.id,
                          resources, stopped, why);
    node_.journal({wall_now_s(), id_, spec.id, "ESCALATION", "SAFE_STOP",
                   "resources [" + resources + "], safe stop commanded for [" + stopped + "]: " + why});
  }

  void node_changed(const bt::NodeSpec& spec, const bt::NodeStatus& status) override {
    TaskControllerNode::NodeStatusRow row;
    auto run = runs_.find(spec.id);
    row.task_id = id_;
    row.node_id = spec.id;
    row.parent_id = parent_of(spec.id);
    row.node_type = bt::to_string(spec.kind);
    row.name = spec.name.empty() ? spec.leaf : spec.name;
    row.state = to_wire(status.state);
    row.code = status.code;
    row.message = status.message;
    row.progress = status.progress.value_or(-1.0);
    row.executor_id = run != runs_.end() ? run->second.executor_id : std::string();
    if (status.started_at) row.started = wall_of(*status.started_at);
    if (status.finished_at) row.finished = wall_of(*status.finished_at);
    row.stamp = dds::wire_now();
    node_.queue_node_status(std::move(row));
    if (status.state != NodeState::kRunning || !status.progress)  // progress lines are not worth a row each
      node_.journal({wall_now_s(), id_, spec.id, "NODE", std::string(bt::to_string(status.state)),
                     status.code.empty() ? status.message : status.code + ": " + status.message});
  }

  void finished(const bt::TaskResult& result) override {
    int state = rigger_task_TASK_FAILED;
    std::string journal_state = "FAILED";
    if (result.outcome == bt::TaskOutcome::kSucceeded) {
      state = rigger_task_TASK_SUCCEEDED;
      journal_state = "SUCCEEDED";
    } else if (result.outcome == bt::TaskOutcome::kCanceled) {
      state = rigger_task_TASK_CANCELED;
      journal_state = "CANCELED";
    }
    // The result lists every escalated safe stop (docs/behavior-tree.md rule 3).
    std::string message = result.message;
    if (!result.escalated.empty()) {
      std::string nodes;
      for (const auto& n : result.escalated) nodes += (nodes.empty() ? "" : ", ") + n;
      message += (message.empty() ? "" : "; ") + std::string("safe stop escalated: ") + nodes;
    }
    node_.flush_side_effects();  // the task's row comes after its timeline
    if (!node_.journal_.finish_task(id_, journal_state, result.code, message, wall_now_s()))
      node_.ctx_.log->error("journal write failed task={}: {}", id_, node_.journal_.last_error());
    node_.publish_task(id_, state, result.code, message, result.origin);
    node_.ctx_.log->info("task finished task={} outcome={} code={} origin={} message={}", id_,
                         bt::to_string(result.outcome), result.code, result.origin, message);
    TaskControllerNode* node = &node_;
    std::string id = id_;
    node_.ctx_.loop.post([node, id] { node->forget_task(id); });
  }

  /// Publishes the prompt of `spec` (active) or its withdrawal (inactive).
  void write_prompt(const std::string& prompt_id, const bt::NodeSpec& spec, bool active) {
    rigger_operator_ui_OperatorPrompt p{};
    const std::string kind = "decision";
    const std::string empty;
    std::vector<char*> storage;
    p.prompt_id = dds::wire_string(prompt_id);
    p.task_id = dds::wire_string(id_);
    p.node_id = dds::wire_string(spec.id);
    p.kind = dds::wire_string(kind);
    p.title = dds::wire_string(spec.name);
    p.text = dds::wire_string(spec.prompt);
    dds::wire_string_sequence(p.options, spec.options, storage);
    p.details_json = dds::wire_string(empty);
    p.timeout_s = 0;
    p.active = active;
    p.stamp = dds::wire_now();
    node_.prompts_.write(p);
  }

 private:
  void send(const bt::NodeSpec& spec, const LeafRun& run, rigger_skill_SkillCommandKind kind, const std::string& params,
            const std::string& reason) {
    rigger_skill_SkillCommand c{};
    c.executor_id = dds::wire_string(run.executor_id);
    c.task_id = dds::wire_string(id_);
    c.node_id = dds::wire_string(spec.id);
    c.skill = dds::wire_string(spec.leaf);
    c.kind = kind;
    c.params_json = dds::wire_string(params);
    c.reason = dds::wire_string(reason);
    c.seq = run.start_seq;
    c.stamp = dds::wire_now();
    if (node_.commands_.write(c) != DDS_RETCODE_OK)
      node_.ctx_.log->error("skill command write failed task={} node={}", id_, spec.id);
  }

  TaskControllerNode& node_;
  std::string id_;
  std::vector<std::string> resources_;
  std::unique_ptr<bt::Engine> engine_;
  std::map<std::string, LeafRun> runs_;
  std::map<bt::TimerId, dds::EventLoop::TimerId> timers_;
  std::map<std::string, std::pair<std::string, bt::Activation>> prompts_;
};

namespace {
/// The skill-command writer's QoS: commands() with MANUAL_BY_PARTICIPANT liveliness, asserted by
/// run_service's loop every kDefaultLease / 3.
dds::Qos supervised_commands(std::chrono::milliseconds lease) {
  dds::Qos q = dds::qos::commands();
  q.manual_liveliness(lease);
  return q;
}
}  // namespace

TaskControllerNode::TaskControllerNode(dds::ServiceContext& ctx)
    : ctx_(ctx),
      journal_(ctx.config.get<std::string>("journal_path", "task_controller_journal.sqlite"),
               ctx.config.get_enum("journal_sync", "normal", {"normal", "full"}) == "full" ? JournalSync::kFull
                                                                                       : JournalSync::kNormal),
      announcements_(ctx.participant, protocol::skill::kExecutors, dds::qos::state()),
      // Executors watch this writer's liveliness: a controller that dies or hangs has its running skills
      // shut down by their executors within the lease (no orphaned motion).
      commands_(ctx.participant, protocol::skill::kCommand,
                supervised_commands(std::chrono::milliseconds(
                    ctx.config.get_in_range<unsigned>("command_lease_ms", 300U, 200U, 10000U)))),
      events_(ctx.participant, protocol::skill::kEvent),
      recipes_(ctx.participant, protocol::task::kRecipe),
      task_commands_(ctx.participant, protocol::task::kCommand),
      task_status_(ctx.participant, protocol::task::kStatus),
      node_status_(ctx.participant, protocol::task::kNodeStatus),
      journal_queries_(ctx.participant, protocol::task::kJournalQuery),
      journal_replies_(ctx.participant, protocol::task::kJournalReply),
      prompts_(ctx.participant, protocol::operator_ui::kPrompt.name, dds::qos::state()),
      responses_(ctx.participant, protocol::operator_ui::kResponse),
      safe_stops_(ctx.participant) {
  validator_options_.default_stop_timeout =
      bt::Seconds(ctx.config.get_in_range<double>("default_stop_timeout_s", 5.0, 0.01, 600.0));
  validator_options_.limits.max_bytes =
      ctx.config.get_in_range<unsigned>("max_recipe_bytes", 4U * 1024U * 1024U, 1024U, static_cast<unsigned>(recipe::kMaxRecipeBytesCeiling));
  validator_options_.limits.max_depth = ctx.config.get_in_range<unsigned>("max_recipe_depth", 128U, 8U, 1024U);
  executor_wait_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(ctx.config.get_in_range<double>("executor_wait_s", 2.0, 0.0, 600.0)));
  condition_timeout_ = std::chrono::milliseconds(
      ctx.config.get_in_range<unsigned>("condition_timeout_ms", 1000U, 10U, 60000U));
  ctx.config.finish();
  world_ = std::make_unique<world_client::WorldClient>(ctx.participant, ctx.loop, ctx.log,
                                                       "task_controller-" + ctx.options.id);

  ctx.loop.on_data(announcements_, [this] { on_announcements(); });
  // A lease expiry also shows as a NOT_ALIVE instance, but waking on the status makes sure we look.
  ctx.loop.on_status(announcements_.handle(), DDS_LIVELINESS_CHANGED_STATUS, [this] { on_announcements(); });
  ctx.loop.on_data(events_, [this] { on_events(); });
  ctx.loop.on_data(recipes_, [this] { on_recipes(); });
  ctx.loop.on_data(task_commands_, [this] { on_task_commands(); });
  ctx.loop.on_data(journal_queries_, [this] { on_journal_queries(); });
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
}

void TaskControllerNode::journal(const JournalRecord& record) {
  post_flush_if_idle();
  journal_backlog_.push_back(record);
}

void TaskControllerNode::queue_node_status(NodeStatusRow row) {
  post_flush_if_idle();
  status_backlog_.push_back(std::move(row));
}

void TaskControllerNode::post_flush_if_idle() {
  // The first queued item posts the flush; later ones ride along with it.
  if (journal_backlog_.empty() && status_backlog_.empty()) ctx_.loop.post([this] { flush_side_effects(); });
}

void TaskControllerNode::flush_side_effects() {
  for (const auto& row : status_backlog_) {
    rigger_task_NodeStatus s{};
    s.task_id = dds::wire_string(row.task_id);
    s.node_id = dds::wire_string(row.node_id);
    s.parent_id = dds::wire_string(row.parent_id);
    s.node_type = dds::wire_string(row.node_type);
    s.name = dds::wire_string(row.name);
    s.state = row.state;
    s.code = dds::wire_string(row.code);
    s.message = dds::wire_string(row.message);
    s.progress = row.progress;
    const std::string no_progress_text;  // named: wire_string() keeps a pointer into it until write()
    s.progress_text = dds::wire_string(no_progress_text);
    s.executor_id = dds::wire_string(row.executor_id);
    s.started = row.started;
    s.finished = row.finished;
    s.stamp = row.stamp;
    if (node_status_.write(s) != DDS_RETCODE_OK)
      ctx_.log->error("node status write failed task={} node={}", row.task_id, row.node_id);
  }
  status_backlog_.clear();
  if (journal_backlog_.empty()) return;
  if (!journal_.add_records(journal_backlog_))
    ctx_.log->error("journal write failed: {} rows lost, first task={} kind={}: {}", journal_backlog_.size(),
                    journal_backlog_.front().task_id, journal_backlog_.front().kind, journal_.last_error());
  journal_backlog_.clear();
}

void TaskControllerNode::report_interrupted() {
  for (const auto& t : journal_.unfinished_tasks()) {
    const std::string message = "the task controller stopped while the task ran; it is not resumed";
    journal_.finish_task(t.task_id, "INTERRUPTED", codes::kInterrupted, message, wall_now_s());
    publish_task(t.task_id, rigger_task_TASK_FAILED, codes::kInterrupted, message, "");
    ctx_.log->warn("task interrupted task={}", t.task_id);
  }
}

// --- executors ---

void TaskControllerNode::on_announcements() {
  std::vector<std::string> lost;
  bool appeared = false;
  announcements_.take(
      [&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t& info) {
        const std::string id = dds::to_string(a.executor_id);
        auto& ex = executors_[id];
        const bool alive = info.instance_state == DDS_IST_ALIVE;
        if (ex.alive && !alive) lost.push_back(id);
        if (alive && !ex.alive) ctx_.log->info("executor up executor={}", id);
        appeared = appeared || alive;
        ex.alive = alive;
        const std::string text = dds::to_string(a.library_json);
        try {
          ex.library = nlohmann::json::parse(text);
        } catch (const std::exception& e) {
          ctx_.log->warn("executor library unreadable executor={}: {}", id, e.what());
          ex.library = nlohmann::json();
        }
        ex.skills.clear();
        for (const auto& s : dds::to_string_vector(a.skills)) ex.skills.insert(s);
      },
      [&](const rigger_skill_ExecutorAnnouncement& key, const dds_sample_info_t& info) {
        auto it = executors_.find(dds::to_string(key.executor_id));
        if (it == executors_.end() || info.instance_state == DDS_IST_ALIVE) return;
        if (it->second.alive) lost.push_back(it->first);
        it->second.alive = false;
      });
  for (const auto& id : lost) executor_lost(id);
  if (appeared) retry_pending();
}

void TaskControllerNode::retry_pending() {
  std::vector<std::string> ids;
  for (const auto& [id, p] : pending_) ids.push_back(id);
  for (const auto& id : ids) {
    auto it = pending_.find(id);
    if (it == pending_.end()) continue;
    const std::string text = it->second.text;
    ctx_.loop.cancel(it->second.timer);
    pending_.erase(it);
    handle_recipe(id, text, true);
  }
}

void TaskControllerNode::executor_lost(const std::string& executor_id) {
  ctx_.log->warn("executor lost executor={}", executor_id);
  std::vector<std::string> task_ids;
  for (const auto& [id, task] : tasks_) task_ids.push_back(id);
  for (const auto& task_id : task_ids) {
    auto it = tasks_.find(task_id);
    if (it == tasks_.end()) continue;
    Task& task = *it->second;
    std::vector<std::pair<std::string, bt::Activation>> hit;
    for (const auto& [node_id, run] : task.runs())
      if (run.executor_id == executor_id) hit.emplace_back(node_id, run.activation);
    for (const auto& [node_id, activation] : hit) {
      auto index = task.engine().find(node_id);
      if (!index) continue;
      const auto& st = task.engine().status(*index);
      if (st.activation != activation || (st.state != NodeState::kRunning && st.state != NodeState::kStopping))
        continue;
      const auto r = task.engine().on_leaf_lost(node_id, activation, "executor " + executor_id + " lost liveliness");
      task.log_result("executor lost", node_id, r);
      if (task.done()) break;
    }
  }
}

skill::SkillLibrary TaskControllerNode::live_library() const {
  skill::SkillLibrary library;
  for (const auto& [id, ex] : executors_) {
    if (!ex.alive || ex.library.is_null()) continue;
    auto parsed = skill::SkillLibrary::parse(ex.library);
    if (!parsed.value) {
      ctx_.log->warn("executor library invalid executor={} errors={}", id, parsed.errors.size());
      continue;
    }
    for (const auto& e : library.merge(*parsed.value))
      ctx_.log->warn("executor library conflict executor={} at {}: {}", id, e.pointer, e.message);
  }
  // The conditions the controller evaluates itself (evaluate_condition) need no executor; an executor
  // that announces one as well keeps its description.
  for (const auto& [name, description] : controller_conditions().descriptions())
    if (library.find(name) == nullptr) library.add(description);
  return library;
}

std::string TaskControllerNode::pick_executor(const std::string& skill, const std::string& pinned) const {
  if (!pinned.empty()) {
    auto it = executors_.find(pinned);
    return it != executors_.end() && it->second.alive && it->second.skills.count(skill) ? pinned : std::string();
  }
  for (const auto& [id, ex] : executors_)
    if (ex.alive && ex.skills.count(skill)) return id;
  return {};
}

// --- tasks ---

void TaskControllerNode::publish_task(const std::string& task_id, int state, const std::string& code,
                                      const std::string& message, const std::string& failed_node,
                                      const std::vector<recipe::Error>& errors) {
  rigger_task_TaskStatus s{};
  std::vector<rigger_task_RecipeError> wire_errors;
  // A rejected hostile recipe may have very many errors; the first ones tell the story.
  constexpr std::size_t kMaxErrors = 200;
  for (std::size_t i = 0; i < errors.size() && i < kMaxErrors; ++i)
    wire_errors.push_back({dds::wire_string(errors[i].pointer), dds::wire_string(errors[i].message)});
  s.task_id = dds::wire_string(task_id);
  s.state = static_cast<rigger_task_TaskState>(state);
  s.code = dds::wire_string(code);
  s.message = dds::wire_string(message);
  s.failed_node = dds::wire_string(failed_node);
  dds::wire_sequence(s.errors, wire_errors);
  s.stamp = dds::wire_now();
  s.submitted = s.stamp;
  if (task_status_.write(s) != DDS_RETCODE_OK) ctx_.log->error("task status write failed task={}", task_id);
}

void TaskControllerNode::reject(const std::string& task_id, const std::string& code, const std::string& message,
                                const std::vector<recipe::Error>& errors) {
  ctx_.log->warn("recipe rejected task={} code={} errors={} message={}", task_id, code, errors.size(), message);
  publish_task(task_id, rigger_task_TASK_REJECTED, code, message, "", errors);
}

void TaskControllerNode::on_recipes() {
  recipes_.take([this](const rigger_task_Recipe& r, const dds_sample_info_t&) {
    const std::string task_id = dds::to_string(r.task_id);
    // Whatever is in the text, a failure here must never take the controller down.
    try {
      handle_recipe(task_id, r.recipe_json ? std::string(r.recipe_json) : std::string(), true);
    } catch (const std::exception& e) {
      reject(task_id, codes::kInvalidRecipe, std::string("recipe could not be handled: ") + e.what());
    }
  });
}

void TaskControllerNode::handle_recipe(const std::string& task_id, const std::string& text, bool may_wait) {
  if (task_id.empty()) {
    reject(task_id, codes::kInvalidRecipe, "the Recipe sample has an empty task_id");
    return;
  }
  if (tasks_.count(task_id) || journal_.has_task(task_id) || pending_.count(task_id)) {
    reject(task_id, codes::kDuplicateTask, "task id " + task_id + " was already used; submit under a new id");
    return;
  }
  recipe::RecipeValidator validator(live_library(), validator_options_);
  auto result = validator.validate_text(text);
  const bool only_unknown_leaves =
      !result.ok() && std::all_of(result.errors.begin(), result.errors.end(), [](const recipe::Error& e) {
        return e.message.rfind("unknown skill", 0) == 0 || e.message.rfind("unknown monitor", 0) == 0;
      });
  if (only_unknown_leaves && may_wait && executor_wait_.count() > 0) {
    // Perhaps its executor has not been discovered yet: wait for announcements, then decide.
    auto& p = pending_[task_id];
    if (p.timer == 0) {
      p.text = text;
      ctx_.log->info("recipe waits for executors task={} first={}", task_id, result.errors.front().message);
      p.timer = ctx_.loop.after(executor_wait_, [this, task_id] {
        auto it = pending_.find(task_id);
        if (it == pending_.end()) return;
        const std::string pending_text = it->second.text;
        pending_.erase(it);
        handle_recipe(task_id, pending_text, false);
      });
    }
    return;
  }
  if (!result.ok()) {
    const std::string message = std::to_string(result.errors.size()) + " error(s); first: " +
                                result.errors.front().pointer + ": " + result.errors.front().message;
    reject(task_id, codes::kInvalidRecipe, message, result.errors);
    return;
  }
  auto& recipe = *result.recipe;
  if (recipe.task_id != task_id) {
    reject(task_id, codes::kInvalidRecipe, "task_id differs from the Recipe sample's",
           {{"/task_id", "expected \"" + task_id + "\" (the Recipe sample's task_id), got \"" + recipe.task_id + "\""}});
    return;
  }
  for (const auto& [other_id, other] : tasks_) {
    std::string common;
    if (!other->done() && intersects(recipe.resources, other->resources(), common)) {
      reject(task_id, codes::kResourceConflict,
             "resource " + common + " is claimed by running task " + other_id + "; wait for it or cancel it");
      return;
    }
  }
  // Journal before acting: a crash from here on leaves the task unfinished in the journal.
  flush_side_effects();  // the journal in the order things happened
  if (!journal_.add_task(task_id, text, wall_now_s())) {
    reject(task_id, codes::kJournalError, "journal write failed: " + journal_.last_error());
    return;
  }
  std::unique_ptr<Task> task;
  try {
    task = std::make_unique<Task>(*this, std::move(recipe), task_id);
  } catch (const bt::SpecError& e) {
    journal_.finish_task(task_id, "FAILED", codes::kInvalidRecipe, e.what(), wall_now_s());
    reject(task_id, codes::kInvalidRecipe, e.what());
    return;
  }
  publish_task(task_id, rigger_task_TASK_ACCEPTED, "", "", "");
  ctx_.log->info("task accepted task={} nodes={}", task_id, task->engine().spec().nodes.size());
  Task& t = *task;
  tasks_[task_id] = std::move(task);
  publish_task(task_id, rigger_task_TASK_RUNNING, "", "", "");
  const auto r = t.engine().start();
  t.log_result("start", "root", r);
}

void TaskControllerNode::forget_task(const std::string& task_id) {
  auto it = tasks_.find(task_id);
  if (it != tasks_.end() && it->second->done()) tasks_.erase(it);
}

// --- executor events ---

void TaskControllerNode::on_events() {
  events_.take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t& info) {
    const std::string task_id = dds::to_string(e.task_id);
    const std::string node_id = dds::to_string(e.node_id);
    const std::string executor_id = dds::to_string(e.executor_id);
    auto& last = last_event_seq_[info.publication_handle];
    if (e.seq <= last) {
      ctx_.log->warn("event rejected (duplicate or out of order) executor={} task={} node={} seq={} last={}",
                     executor_id, task_id, node_id, e.seq, last);
      journal({wall_now_s(), task_id, node_id, "REJECTED_EVENT", "OUT_OF_ORDER",
               "from " + executor_id + " seq " + std::to_string(e.seq) + " after " + std::to_string(last)});
      return;
    }
    last = e.seq;
    auto task_it = tasks_.find(task_id);
    if (task_it == tasks_.end()) {
      ctx_.log->warn("event rejected (unknown task) executor={} task={} node={}", executor_id, task_id, node_id);
      return;
    }
    Task& task = *task_it->second;
    auto run_it = task.runs().find(node_id);
    if (run_it == task.runs().end() || run_it->second.executor_id != executor_id) {
      ctx_.log->warn("event rejected (unknown node or executor) executor={} task={} node={}", executor_id, task_id,
                     node_id);
      journal({wall_now_s(), task_id, node_id, "REJECTED_EVENT", "UNKNOWN", "from " + executor_id});
      return;
    }
    if (e.command_seq != run_it->second.start_seq) {
      ctx_.log->warn("event rejected (stale) executor={} task={} node={} command_seq={} current={}", executor_id,
                     task_id, node_id, e.command_seq, run_it->second.start_seq);
      journal({wall_now_s(), task_id, node_id, "REJECTED_EVENT", "STALE",
               "command_seq " + std::to_string(e.command_seq) + " is not the current START " +
                   std::to_string(run_it->second.start_seq)});
      return;
    }
    bt::LeafEvent ev;
    ev.activation = run_it->second.activation;
    ev.code = dds::to_string(e.code);
    ev.message = dds::to_string(e.message);
    switch (e.kind) {
      case rigger_skill_SKILL_EVENT_SUCCESS: ev.kind = bt::LeafEventKind::kSuccess; break;
      case rigger_skill_SKILL_EVENT_FAILURE: ev.kind = bt::LeafEventKind::kFailure; break;
      case rigger_skill_SKILL_EVENT_STOPPED: ev.kind = bt::LeafEventKind::kStopped; break;
      default:
        ev.kind = bt::LeafEventKind::kProgress;
        if (e.progress >= 0.0 && e.progress <= 1.0) ev.progress = e.progress;
        break;
    }
    if (ev.kind != bt::LeafEventKind::kProgress)
      journal({wall_now_s(), task_id, node_id, "EVENT", std::string(bt::to_string(ev.kind)),
               ev.code.empty() ? ev.message : ev.code + ": " + ev.message});
    task.log_result("event", node_id, task.engine().on_leaf_event(node_id, ev));
  });
}

// --- commands, operator, journal ---

void TaskControllerNode::on_task_commands() {
  task_commands_.take([this](const rigger_task_TaskCommand& c, const dds_sample_info_t&) {
    const std::string task_id = dds::to_string(c.task_id);
    const std::string reason = dds::to_string(c.reason).empty() ? "requested by " + dds::to_string(c.issuer)
                                                                 : dds::to_string(c.reason);
    auto it = tasks_.find(task_id);
    if (it == tasks_.end() || it->second->done()) {
      ctx_.log->warn("task command for a task not running task={} kind={}", task_id, static_cast<int>(c.kind));
      return;
    }
    Task& task = *it->second;
    bt::EventResult r;
    const char* what = "cancel";
    if (c.kind == rigger_task_TASK_CANCEL) {
      journal({wall_now_s(), task_id, "", "COMMAND", "CANCEL", reason});
      r = task.engine().cancel(reason);
    } else if (c.kind == rigger_task_TASK_PAUSE) {
      what = "pause";
      journal({wall_now_s(), task_id, "", "COMMAND", "PAUSE", reason});
      r = task.engine().pause();
      if (r.acted_on()) publish_task(task_id, rigger_task_TASK_PAUSED, "", reason, "");
    } else {
      what = "resume";
      journal({wall_now_s(), task_id, "", "COMMAND", "RESUME", reason});
      r = task.engine().resume();
      if (r.acted_on()) publish_task(task_id, rigger_task_TASK_RUNNING, "", reason, "");
    }
    task.log_result(what, "", r);
  });
}

void TaskControllerNode::on_operator_responses() {
  responses_.take([this](const rigger_operator_ui_OperatorResponse& resp, const dds_sample_info_t&) {
    const std::string prompt_id = dds::to_string(resp.prompt_id);
    const std::string answer = dds::to_string(resp.answer);
    const std::string by = dds::to_string(resp.operator_id);
    // Prompt ids are "<task>#<node>#<activation>" (Task::ask_operator).
    const auto hash = prompt_id.find('#');
    if (hash == std::string::npos) {
      ctx_.log->warn("operator answer rejected: prompt id {} is not one of ours", prompt_id);
      return;
    }
    const std::string task_id = prompt_id.substr(0, hash);
    const auto node_end = prompt_id.find('#', hash + 1);
    const std::string prompt_node =
        prompt_id.substr(hash + 1, node_end == std::string::npos ? std::string::npos : node_end - hash - 1);
    auto it = tasks_.find(task_id);
    if (it == tasks_.end() || it->second->prompts().count(prompt_id) == 0) {
      // Answered, withdrawn (the task was canceled or its branch shut down) or never asked.
      ctx_.log->warn("operator answer rejected: prompt {} is not open answer={} by={}", prompt_id, answer, by);
      if (journal_.has_task(task_id))
        journal({wall_now_s(), task_id, prompt_node, "REJECTED_EVENT", "NOT_ASKED",
                 "answer \"" + answer + "\" by " + by + " to prompt " + prompt_id +
                     ", which is not open (answered, withdrawn or task ended)"});
      return;
    }
    Task& task = *it->second;
    auto p = task.prompts().find(prompt_id);
    const auto [node_id, activation] = p->second;
    auto index = task.engine().find(node_id);
    if (!index) return;
    const auto& spec = task.engine().spec().nodes[*index];
    const auto& options = spec.options;
    std::size_t choice = options.size();
    for (std::size_t i = 0; i < options.size(); ++i)
      if (options[i] == answer) choice = i;
    if (choice == options.size()) {
      std::string expected;
      for (const auto& o : options) expected += (expected.empty() ? "\"" : ", \"") + o + "\"";
      ctx_.log->warn("operator answer not an option prompt={} answer={} expected={}", prompt_id, answer, expected);
      journal({wall_now_s(), task.id(), node_id, "REJECTED_EVENT", "NOT_AN_OPTION",
               "answer \"" + answer + "\" by " + by + ": expected one of " + expected});
      return;
    }
    task.prompts().erase(p);
    journal({wall_now_s(), task.id(), node_id, "OPERATOR", "ANSWER", answer + " by " + by});
    // The question is settled: withdraw it so that no operator UI keeps showing it.
    task.write_prompt(prompt_id, spec, false);
    task.log_result("operator decision", node_id, task.engine().on_operator_decision(node_id, activation, choice));
  });
}

void TaskControllerNode::on_journal_queries() {
  flush_side_effects();  // a query sees every row queued so far
  journal_queries_.take([this](const rigger_task_JournalQuery& q, const dds_sample_info_t&) {
    const std::string task_id = dds::to_string(q.task_id);
    const std::size_t max = q.max_entries == 0 ? 1000 : std::min<std::uint32_t>(q.max_entries, 10000);
    std::vector<JournalRecord> records;
    if (task_id.empty()) {
      for (const auto& t : journal_.tasks(max)) records.push_back({t.submitted_s, t.task_id, t.task_id, "TASK", t.state, ""});
    } else {
      records = journal_.timeline(task_id, max);
    }
    std::vector<rigger_task_JournalEntry> entries;
    for (const auto& r : records) {
      rigger_task_JournalEntry e{};
      e.stamp = dds::to_wire(std::chrono::system_clock::time_point(
          std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::duration<double>(r.stamp_s))));
      e.node_id = dds::wire_string(r.node_id);
      e.kind = dds::wire_string(r.kind);
      e.code = dds::wire_string(r.code);
      e.message = dds::wire_string(r.message);
      entries.push_back(e);
    }
    rigger_task_JournalReply reply{};
    const std::string message = !task_id.empty() && records.empty() ? "no such task in the journal" : "";
    reply.client_id = q.client_id;
    reply.request_id = q.request_id;
    reply.ok = message.empty();
    reply.message = dds::wire_string(message);
    dds::wire_sequence(reply.entries, entries);
    journal_replies_.write(reply);
  });
}

}  // namespace rigger::task_controller
