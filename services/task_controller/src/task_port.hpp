#pragma once
/// @file
/// One running task: its bt::Engine and the bt::Port through which the engine acts — START/SHUTDOWN to
/// executors, conditions through the world model, operator prompts, timers on the event loop, safe-stop
/// escalation, node status and journal rows. Also routes what arrives for the task (executor events,
/// task commands, operator answers, a lost executor) into the engine. What it needs from the controller
/// is the TaskHost interface (the node implements it).

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "journal.hpp"
#include "leaf_run.hpp"
#include "operator_decisions.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/bt/engine.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/world_client/world_client.hpp"
#include "status_publisher.hpp"

namespace rigger::task_controller {

/// Codes the controller adds to the engine's (RejectCode, recipe_admission.hpp, has the admission ones).
namespace codes {
inline constexpr const char* kInterrupted = "INTERRUPTED";
/// Resume after a crash: the rebuilt task waits for the operator (TaskStatus PAUSED with this code).
inline constexpr const char* kResumeConfirmation = "RESUME_CONFIRMATION";
/// Resume after a crash refused (recipe no longer valid, journal unusable, task being canceled, …).
inline constexpr const char* kResumeRefused = "RESUME_REFUSED";
/// The operator answered `abort` to the resume prompt: the task ends FAILED, nothing started.
inline constexpr const char* kResumeAborted = "RESUME_ABORTED";
inline constexpr const char* kNoExecutor = "NO_EXECUTOR";
/// The executor did not answer a START (ACCEPTED or FAILURE) within start_answer_timeout_s.
inline constexpr const char* kStartUnanswered = "START_UNANSWERED";
/// A run of another task (or of an earlier controller) held a resource of the leaf for busy_wait_s.
inline constexpr const char* kResourceHeld = "RESOURCE_HELD";
/// Journal code of a START sent again (same seq, same writer) because its executor had not answered.
inline constexpr const char* kStartSentAgain = "START_SENT_AGAIN";
/// Journal code of a START held back while another task's run holds a resource of the leaf.
inline constexpr const char* kStartWaits = "START_WAITS";
/// A held START whose leaf was shut down before it could be sent.
inline constexpr const char* kNotStarted = "NOT_STARTED";
/// Journal code of the row that counts a run's PROGRESS events beyond journal_progress_per_run.
inline constexpr const char* kProgressLeftOut = "PROGRESS_LEFT_OUT";
}  // namespace codes

class Task;

/// What a task needs from its controller.
class TaskHost {
 public:
  virtual ~TaskHost() = default;
  virtual dds::EventLoop& loop() = 0;
  virtual const Logger& log() const = 0;
  /// The running task `id`, or nullptr (it ended and was forgotten).
  virtual Task* find_task(const std::string& id) = 0;
  /// The live executor for `skill` (ExecutorDirectory::pick).
  virtual std::string pick_executor(const std::string& skill, const std::string& pinned) const = 0;
  /// Which run of another task than `task_id` holds one of `resources`, as the executors announced it
  /// (ExecutorDirectory::Holder::describe), or "" when they are free. `started` (a resumed task): only
  /// its runs of these nodes are its own, and a run of `node_id` itself that this controller did not
  /// start holds it (ExecutorDirectory::holder).
  virtual std::string holder_of(const std::vector<std::string>& resources, const std::string& task_id,
                                const std::set<std::string>* started = nullptr,
                                const std::string& node_id = "") const = 0;
  /// How long a START waits for its resources to be freed before the leaf fails RESOURCE_HELD.
  virtual std::chrono::nanoseconds busy_wait() const = 0;
  /// How many PROGRESS events of one run are journaled (the rest are counted in one row at its end).
  virtual unsigned progress_rows_per_run() const = 0;
  virtual ControllerEndpoint& endpoint() = 0;
  virtual PromptWriter& prompts() = 0;
  /// Queues a journal row / node status sample; they are written right after the current handler.
  virtual void journal(const JournalRecord& record) = 0;
  virtual void node_status(NodeStatusRow row) = 0;
  /// Asks the world model whether `object` is localized (the answer comes on a later loop turn).
  virtual void is_localized(const std::string& object, double max_age_s,
                            std::function<void(const world_client::Reply&)> answer) = 0;
  /// Leaf `node_id` of task `task_id`, which localizes `object`, succeeded: the host journals the
  /// object's pose as the world model has it now (relocalization.hpp), for a resume after a crash.
  virtual void localized(const std::string& task_id, const std::string& node_id, const std::string& object) {
    (void)task_id, (void)node_id, (void)object;
  }
  /// How long an executor has to answer a START before the leaf fails START_UNANSWERED.
  virtual std::chrono::nanoseconds start_answer_timeout() const = 0;
  /// How long an unanswered START waits before it is sent again (Task::arm_resend).
  virtual std::chrono::nanoseconds start_resend() const = 0;
  /// Commands a safe stop of `resource`; false when the write failed.
  virtual bool safe_stop(const std::string& resource, const std::string& reason) = 0;
  /// The task ended: record and publish its result (`state`: the wire TaskState, `journal_state` the
  /// journal's), then forget it on a later turn.
  virtual void task_finished(const std::string& id, int state, const std::string& journal_state,
                             const bt::TaskResult& result, const std::string& message) = 0;
};

class Task : public bt::Port {
 public:
  /// @throws bt::SpecError when the engine refuses the tree.
  Task(TaskHost& host, recipe::ValidatedRecipe recipe, std::string id);
  ~Task() override;

  const std::string& id() const { return id_; }
  bt::Engine& engine() { return *engine_; }
  const std::vector<std::string>& resources() const { return resources_; }
  bool done() const { return engine_->result().has_value(); }

  /// A task resumed after a controller crash: its STARTs also wait while a run of the same task id (the
  /// killed controller's, still announced) holds one of their resources. Call before the engine starts.
  void mark_resumed() { resumed_ = true; }
  /// The leaves that localize an object (node id → object, relocalization.hpp localizing_leaves): when
  /// one succeeds, TaskHost::localized is called.
  void set_localizing(std::map<std::string, std::string> leaves) { localizing_ = std::move(leaves); }
  /// Logs and journals an engine result that was not acted on.
  void log_result(const char* what, const std::string& node_id, const bt::EventResult& r);

  /// An in-order executor event for this task (ControllerEndpoint::take).
  void on_event(const ReceivedEvent& e);
  /// Executor `executor_id` lost liveliness: its running leaves fail.
  void executor_lost(const std::string& executor_id);
  /// Sends the held STARTs whose resources are free now (the node calls it after every announcement).
  void start_held();
  bool holds_starts() const { return !held_.empty(); }
  /// CANCEL / PAUSE / RESUME (rigger/task/command) by `issuer`. Returns the TaskState to publish with
  /// `reason` (PAUSED, RUNNING), or -1 for none. PAUSE also sends PAUSE to every running leaf (each
  /// answers PAUSED, journaled: held, or not pausable and running on); RESUME sends RESUME to those, then
  /// the starts held meanwhile go out.
  int command(rigger_task_TaskCommandKind kind, const std::string& reason, const std::string& issuer);
  /// An answer to prompt `id` (of this task) by `by`.
  void answer(const PromptId& id, const std::string& answer, const std::string& by);
  /// Whether prompt `id` is open (asked, not answered nor withdrawn).
  bool prompt_open(const PromptId& id) const { return prompts_.count(id.str()) != 0; }

  // --- bt::Port ---
  bt::TimePoint now() override { return bt::Clock::now(); }
  void start_leaf(const bt::NodeSpec& spec, bt::Activation activation) override;
  void shutdown_leaf(const bt::NodeSpec& spec, bt::Activation activation, const std::string& reason) override;
  void evaluate_condition(const bt::NodeSpec& spec, bt::Activation activation) override;
  void ask_operator(const bt::NodeSpec& spec, bt::Activation activation) override;
  void withdraw_operator_request(const bt::NodeSpec& spec, bt::Activation activation) override;
  void schedule(bt::TimerId id, bt::TimePoint deadline) override;
  void cancel_timer(bt::TimerId id) override;
  void escalate_safe_stop(const bt::NodeSpec& spec, const std::string& why) override;
  void node_changed(const bt::NodeSpec& spec, const bt::NodeStatus& status) override;
  void finished(const bt::TaskResult& result) override;

 private:
  /// Runs `fn` on the engine later (outside any Port callback), if the task still exists then.
  void defer(std::function<void(Task&)> fn);
  /// A START held back while runs of another task hold a resource of the leaf (`holder` says which).
  struct Held {
    bt::Activation activation = 0;
    /// busy_wait: then the leaf fails RESOURCE_HELD (START_UNANSWERED when its executor's reader was
    /// never matched)
    dds::EventLoop::TimerId deadline = 0;
    std::string holder;
    /// Its resources were freed while the task was paused: sent on RESUME (deadline then cancelled).
    bool freed = false;
  };
  /// PROGRESS events of a node's current run: the first ones journaled, the others counted.
  struct ProgressRows {
    unsigned journaled = 0;
    unsigned left_out = 0;
  };

  /// Arms the busy_wait deadline of `node_id`'s held START.
  dds::EventLoop::TimerId arm_held(const std::string& node_id, bt::Activation activation);
  /// A held START whose resources are free now: sent, or (task paused) kept until RESUME.
  void release_held(const std::string& node_id);
  /// Sends PAUSE (`pause`) or RESUME to every leaf running now (PAUSE) / paused (RESUME).
  void pause_leaves(bool pause, const std::string& why);
  /// Sends SHUTDOWN of `run` (with a new seq) and journals it.
  void send_shutdown(const bt::NodeSpec& spec, const LeafRun& run, const std::string& reason);
  /// An event the controller decides for a leaf itself (no executor sent it): journaled as one, then
  /// given to the engine; `what` names it in the log if the engine does not act on it.
  void own_event(const std::string& node_id, bt::LeafEventKind kind, bt::Activation activation,
                 const std::string& code, const std::string& message, const char* what);
  /// Picks the executor and sends the START (NO_EXECUTOR when none is live), arming the answer timer.
  void send_start(const bt::NodeSpec& spec, bt::Activation activation);
  /// The START of `node_id` waited busy_wait: sent if its resources are free now, else the leaf fails.
  void held_too_long(const std::string& node_id, bt::Activation activation);
  /// A START unanswered after TaskHost::start_resend is sent again, then after twice and four times that
  /// (kStartResends in all), before start_answer_timeout fails it. A write can reach nobody although
  /// both ends are discovered: a reader that has not yet had its writer's first heartbeat drops what
  /// came before it. The executor takes a seq once (skill_protocol::CommandOrder).
  static constexpr unsigned kStartResends = 3;
  void arm_resend(const std::string& node_id, std::uint64_t start_seq, unsigned sent_again);
  /// `node_id`'s leaf while its START `start_seq` is unanswered and the engine still runs that run;
  /// nullptr otherwise.
  const bt::NodeSpec* unanswered_and_running(const std::string& node_id, std::uint64_t start_seq) const;
  void resend_start(const std::string& node_id, std::uint64_t start_seq, unsigned sent_again);
  /// The answer timer of `node_id`'s START fired: fails the leaf if that START is still unanswered.
  void start_unanswered(const std::string& node_id, std::uint64_t start_seq);
  /// Journals a PROGRESS event of `node_id`'s current run, or counts it beyond the bound.
  void journal_progress(const std::string& node_id, const bt::LeafEvent& event);
  /// The current run of `node_id` ended (or is abandoned): journals how many PROGRESS rows were left out.
  void end_progress(const std::string& node_id);
  /// The START parameters of `spec` (one of the engine's nodes) as JSON text, serialised when the task
  /// was built.
  const std::string& params_text(const bt::NodeSpec& spec) const;

  /// Which run of another task (or, resumed, of the killed controller) holds one of `spec`'s resources.
  std::string held_by(const bt::NodeSpec& spec) const;
  /// What a START of `spec` must wait for: held_by, else the executor it would go to while that
  /// executor's command reader has not matched a writer of the controller yet (`unreachable` set).
  /// "" when it can go now.
  std::string waits_for(const bt::NodeSpec& spec, bool* unreachable = nullptr) const;

  TaskHost& host_;
  std::string id_;
  bool resumed_ = false;
  std::map<std::string, std::string> localizing_;  ///< set_localizing
  std::vector<std::string> resources_;
  std::unique_ptr<bt::Engine> engine_;
  std::vector<std::string> params_text_;  ///< indexed like engine_->spec().nodes; "" for non-leaves
  std::map<std::string, LeafRun> runs_;   ///< by node id: the last START sent
  std::map<std::string, dds::EventLoop::TimerId> unanswered_;  ///< by node id: STARTs not answered yet
  std::map<std::string, dds::EventLoop::TimerId> resends_;     ///< by node id: their next resend (arm_resend)
  std::map<std::string, Held> held_;                           ///< by node id: STARTs not sent yet
  std::map<std::string, bt::Activation> paused_;               ///< by node id: leaves sent PAUSE, not RESUME
  std::map<std::string, ProgressRows> progress_rows_;          ///< by node id, for its current run
  std::map<bt::TimerId, dds::EventLoop::TimerId> timers_;
  std::map<std::string, std::pair<std::string, bt::Activation>> prompts_;  ///< open prompt id → (node, activation)
};

}  // namespace rigger::task_controller
