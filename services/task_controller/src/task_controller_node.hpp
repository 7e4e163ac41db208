#pragma once
/// @file
/// The task controller's DDS node: a thin layer between the topics and the pure engine/validator.
/// It wires one unit per job (each in its own file, the logic in each unit-tested without DDS):
///  - executor_directory: the live executors and their skills (which executor runs a leaf);
///  - recipe_admission: run, wait for an executor, or reject with a typed RejectCode;
///  - leaf_run: which run an executor's event is for and what the engine makes of it (the controller's
///    half of the skill protocol itself is rigger::skill_protocol::ControllerEndpoint);
///  - operator_decisions: prompt ids and answers; journal_server: journal queries;
///  - task_port: one running task, the engine's bt::Port; status_publisher: task and node status;
///  - controller_settings: the configuration keys, read before anything is built.
///
///  - rigger/skill/executors (liveliness-monitored): live executors and the skills they offer; their
///    libraries merged form the skill library recipes are validated against. An executor whose
///    liveliness is lost fails every running leaf bound to it with EXECUTOR_LOST.
///  - rigger/task/recipe: validated (every error with its JSON pointer goes out in TaskStatus REJECTED),
///    checked for resource conflicts with the tasks already running, journalled, then run.
///  - rigger/skill/command and rigger/skill/event: the executor protocol (START/SHUTDOWN with an
///    increasing seq; events must echo the START's seq; unknown, stale, duplicate and out-of-order
///    events are rejected, logged and journalled, never acted on).
///  - rigger/task/status, rigger/task/node_status: results for everyone.
///  - rigger/task/command: CANCEL, PAUSE, RESUME (of a PAUSED or an INTERRUPTED task).
///  - rigger/operator/prompt|response: OperatorDecision, and the resume prompt.
///  - rigger/task/journal_query → journal_reply: the journal's timeline for riggerctl.
/// Nothing polls: the node does work only when data arrives or one of the engine's timers is due.
/// Commands first: a handler sends the START/SHUTDOWN commands it causes at once; the node statuses and
/// journal rows it causes are queued and written together right after it (flush_side_effects()). A
/// controller killed in between loses those rows, never a task: the recipe row was written before the
/// first START, so a restarted controller reports the task INTERRUPTED; a RESUME of it rebuilds the tree
/// from the journal (resume_plan) and starts it once the operator confirms the resume prompt.
///
/// Conditions: ObjectLocalized is answered by the world model (WorldClient) and is always part of the
/// library recipes are validated against (no executor needs to announce it); an unreachable world model
/// fails the Condition with WORLD_UNREACHABLE, an unknown condition with UNKNOWN_CONDITION.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "controller_settings.hpp"
#include "executor_directory.hpp"
#include "journal.hpp"
#include "journal_server.hpp"
#include "leaf_run.hpp"
#include "operator_decisions.hpp"
#include "recipe_admission.hpp"
#include "resume_plan.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service.hpp"
#include "side_effect_writer.hpp"
#include "stage_trace.hpp"
#include "status_publisher.hpp"
#include "task_port.hpp"

namespace rigger::world_client {
class WorldClient;
}

namespace rigger::task_controller {

class TaskControllerNode : public service::Node, private TaskHost {
 public:
  /// `journal_path`: the journal's file instead of the configuration's journal_path (--journal), when
  /// not empty. @throws ConfigError, JournalError, DdsError.
  explicit TaskControllerNode(service::ServiceContext& ctx, const std::string& journal_path = "");
  ~TaskControllerNode() override;

 private:
  // --- TaskHost ---
  dds::EventLoop& loop() override { return ctx_.loop; }
  const Logger& log() const override { return ctx_.log; }
  Task* find_task(const std::string& id) override;
  std::string pick_executor(const std::string& skill, const std::string& pinned) const override {
    return executors_.pick(skill, pinned);
  }
  std::string holder_of(const std::vector<std::string>& resources, const std::string& task_id,
                        const std::set<std::string>* started, const std::string& node_id) const override;
  std::chrono::nanoseconds busy_wait() const override { return settings_.busy_wait; }
  unsigned progress_rows_per_run() const override { return settings_.progress_rows_per_run; }
  ControllerEndpoint& endpoint() override { return endpoint_; }
  PromptWriter& prompts() override { return prompts_; }
  void journal(const JournalRecord& record) override;
  void node_status(NodeStatusRow row) override;
  void is_localized(const std::string& object, double max_age_s,
                    std::function<void(const world_client::Reply&)> answer) override;
  void localized(const std::string& task_id, const std::string& node_id, const std::string& object) override;
  std::chrono::nanoseconds start_answer_timeout() const override { return settings_.start_answer_timeout; }
  std::chrono::nanoseconds start_resend() const override { return settings_.start_resend; }
  bool safe_stop(const std::string& resource, const std::string& reason) override;
  void task_finished(const std::string& id, int state, const std::string& journal_state, const bt::TaskResult& result,
                     const std::string& message) override;

  void on_announcements();
  void executor_lost(const std::string& executor_id);
  void on_recipes();
  /// `may_wait`: hold a recipe whose only errors are unknown skills/monitors (see executor_wait_s).
  void handle_recipe(const std::string& task_id, const std::string& text, bool may_wait);
  /// Decides every pending recipe and RESUME anew (an executor appeared).
  void retry_pending();
  /// Sends every held START that can go now (Task::start_held, for each task that holds one).
  void start_held();
  void on_events();
  void on_task_commands();
  void on_operator_responses();
  void report_interrupted();
  /// RESUME of an INTERRUPTED task (docs/behavior-tree.md "Resume after a crash"): rebuilds its tree
  /// from the journal, plans what is done and what runs, and asks the operator (prompt kind "resume");
  /// nothing starts before the answer. Refusals go out as TaskStatus FAILED, code RESUME_REFUSED.
  /// `may_wait`: a recipe naming a skill or monitor no live executor offers yet waits for announcements
  /// (executor_wait_s), as a new recipe does: a controller just restarted has not heard every executor.
  void resume_interrupted(const std::string& task_id, const std::string& issuer, const std::string& reason,
                          bool may_wait = true);
  void refuse_resume(const std::string& task_id, const std::string& why);
  /// The world model's answer about the `index`-th re-checked object of the resume of `task_id` (check
  /// `serial`); once every object is answered the plan is final and the operator is asked.
  void rechecked(const std::string& task_id, std::uint64_t serial, std::size_t index, const world_client::Reply& reply);
  /// Journals the plan and asks the operator (the world re-check done).
  void ask_resume(const std::string& task_id);
  /// A CANCEL of a task whose resume waits for the operator: withdraws the question, ends it CANCELED.
  /// False when no resume of `task_id` waits. (These live in task_controller_resume.cpp.)
  bool cancel_resuming(const std::string& task_id, const std::string& reason);
  /// The operator's answer to a resume prompt: continue/rerun/skip start the task, abort ends it.
  void answer_resume(const PromptId& id, const std::string& answer, const std::string& by);
  void reject(const std::string& task_id, RejectCode code, const std::string& message,
              const std::vector<recipe::Error>& errors = {});
  /// Hands the queued journal rows and node statuses to the side-effect writer, which writes them on its
  /// own thread (the rows in one transaction, then the statuses). A handler sends its commands (START,
  /// SHUTDOWN) first; this runs flush_delay after the first queued item (post_flush_if_idle).
  void hand_over_side_effects();
  /// The same, and waits until everything handed over is written: before anything that reads the
  /// journal or writes a task row.
  void flush_side_effects();
  void post_flush_if_idle();
  /// Writes the stage trace, with when each batch of side effects was written.
  void write_stage_trace();
  /// Has the loop note each dispatch in the stage trace (its loop marks), naming the event reader's.
  void trace_loop(dds::EventLoop& loop);
  void forget_task(const std::string& task_id);

  service::ServiceContext& ctx_;
  const ControllerSettings settings_;  ///< read first: the members below are built from it
  Journal journal_;
  dds::Reader<rigger_skill_ExecutorAnnouncement> announcements_;
  ControllerEndpoint endpoint_;
  dds::Reader<rigger_task_Recipe> recipes_;
  dds::Reader<rigger_task_TaskCommand> task_commands_;
  StatusPublisher status_;
  JournalServer journal_server_;
  PromptWriter prompts_;
  dds::Reader<rigger_operator_ui_OperatorResponse> responses_;
  safety::SafeStopWriter safe_stops_;

  ExecutorDirectory executors_;
  std::map<std::string, std::unique_ptr<Task>> tasks_;
  /// A recipe, or the RESUME of an INTERRUPTED task, whose recipe names a skill or monitor no live
  /// executor offers yet: `again` decides it anew (may_wait true: on an executor's announcement; false:
  /// once executor_wait_s has passed).
  struct Pending {
    std::function<void(bool may_wait)> again;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::string, Pending> pending_;  ///< by task id
  /// Holds `again` for `task_id` until an executor announces itself (retry_pending) or executor_wait_s
  /// has passed.
  void wait_for_executors(const std::string& task_id, std::function<void(bool may_wait)> again);
  /// An INTERRUPTED task rebuilt for a resume, waiting for the operator's confirmation (not started).
  struct Resuming {
    std::unique_ptr<Task> task;
    ResumePlan plan;
    std::vector<JournalRecord> timeline;  ///< the task's journal rows at the resume (re-planned with)
    std::vector<ObjectRecheck> checks;    ///< the objects re-checked against the world model
    std::size_t unanswered = 0;           ///< checks still waiting for the world model
    std::uint64_t serial = 0;             ///< tells this resume's world answers from a withdrawn one's
    bool asked = false;                   ///< the prompt is out (before: the world is being re-checked)
    PromptId prompt;
    bt::NodeSpec question;  ///< the prompt's title, text and options
    std::string details_json;
    std::string summary;
  };
  std::map<std::string, Resuming> resuming_;          ///< by task id
  std::uint64_t resume_serial_ = 0;
  std::unique_ptr<world_client::WorldClient> world_;  ///< Condition nodes query the world model through it
  std::vector<NodeStatusRow> status_backlog_;
  std::vector<JournalRecord> journal_backlog_;
  bool flush_pending_ = false;                 ///< a flush of the backlogs is scheduled
  dds::EventLoop::TimerId flush_timer_ = 0;    ///< its timer (0: none, or a posted flush)
  std::unique_ptr<StageTrace> trace_;  ///< nullptr unless stage_trace_path is set
  std::vector<std::size_t> traced_upto_;  ///< per batch handed over: trace_'s record count then
  /// Writes the backlogs off the loop thread; declared last, so it ends (writing what is queued) first.
  std::unique_ptr<SideEffectWriter> writer_;
};

}  // namespace rigger::task_controller
