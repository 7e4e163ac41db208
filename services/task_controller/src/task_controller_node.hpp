#pragma once
/// @file
/// The task controller's DDS node: a thin layer between the topics and the pure engine/validator.
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
///  - rigger/task/command: CANCEL, PAUSE, RESUME.  rigger/operator/prompt|response: OperatorDecision.
///  - rigger/task/journal_query → journal_reply: the journal's timeline for riggerctl.
/// Nothing polls: the node does work only when data arrives or one of the engine's timers is due.
/// Commands first: a handler sends the START/SHUTDOWN commands it causes at once; the node statuses and
/// journal rows it causes are queued and written together right after it (flush_side_effects()). A
/// controller killed in between loses those rows, never a task: the recipe row was written before the
/// first START, so a restarted controller reports the task INTERRUPTED.
///
/// Configuration keys (all optional):
///   "journal_path": string, default "task_controller_journal.sqlite"
///   "journal_sync": "normal" (default: no fsync per commit; survives controller crashes and restarts) or
///                   "full" (an fsync per commit; also survives a power cut). See journal.hpp.
///   "default_stop_timeout_s": number in [0.01, 600], default 5
///   "max_recipe_bytes": integer in [1024, 67108864 (recipe::kMaxRecipeBytesCeiling)], default 4194304
///   "max_recipe_depth": integer in [8, 1024], default 128
///   "command_lease_ms": integer in [200, 10000], default 300: the liveliness lease offered on
///                       rigger/skill/command; executors shut down the runs of a controller that lost it
///   "executor_wait_s": number in [0, 600], default 2: a recipe naming a skill no live executor offers
///                      waits this long for one to appear (re-validated on every new announcement)
///                      before it is rejected
///
/// Conditions: ObjectLocalized is answered by the world model (WorldClient) and is always part of the
/// library recipes are validated against (no executor needs to announce it); an unreachable world model
/// fails the Condition with WORLD_UNREACHABLE, an unknown condition with UNKNOWN_CONDITION.

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/bt/engine.hpp"
#include "journal.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"
#include "rigger/safety/safe_stop.hpp"

namespace rigger::world_client {
class WorldClient;
}

namespace rigger::task_controller {

/// Codes the controller adds to the engine's.
namespace codes {
inline constexpr const char* kInvalidRecipe = "INVALID_RECIPE";
inline constexpr const char* kDuplicateTask = "DUPLICATE_TASK";
inline constexpr const char* kResourceConflict = "RESOURCE_CONFLICT";
inline constexpr const char* kInterrupted = "INTERRUPTED";
inline constexpr const char* kJournalError = "JOURNAL_ERROR";
inline constexpr const char* kWorldUnreachable = "WORLD_UNREACHABLE";
inline constexpr const char* kNoExecutor = "NO_EXECUTOR";
}  // namespace codes

class TaskControllerNode : public dds::Node {
 public:
  /// @throws ConfigError, JournalError, DdsError.
  explicit TaskControllerNode(dds::ServiceContext& ctx);
  ~TaskControllerNode() override;

 private:
  struct Executor {
    bool alive = false;
    nlohmann::json library;
    std::set<std::string> skills;
  };
  class Task;

  void on_announcements();
  void executor_lost(const std::string& executor_id);
  void on_recipes();
  /// `may_wait`: hold a recipe whose only errors are unknown skills/monitors (see executor_wait_s).
  void handle_recipe(const std::string& task_id, const std::string& text, bool may_wait);
  void retry_pending();
  void on_events();
  void on_task_commands();
  void on_operator_responses();
  void on_journal_queries();
  void report_interrupted();

  skill::SkillLibrary live_library() const;
  /// The live executor that runs `skill` (pinned one when `pinned` is set), or "".
  std::string pick_executor(const std::string& skill, const std::string& pinned) const;
  void publish_task(const std::string& task_id, int state, const std::string& code, const std::string& message,
                    const std::string& failed_node, const std::vector<recipe::Error>& errors = {});
  void reject(const std::string& task_id, const std::string& code, const std::string& message,
              const std::vector<recipe::Error>& errors = {});
  /// Queues a journal row; see flush_side_effects().
  void journal(const JournalRecord& record);
  /// Writes the queued node statuses and journal rows (one transaction). A handler sends its commands
  /// (START, SHUTDOWN) first; this runs once it returned, on the loop's next turn (posted by the first
  /// queued item), and before anything that reads the journal or writes a task row.
  void flush_side_effects();
  struct NodeStatusRow;
  /// Queues a node status sample, like journal().
  void queue_node_status(NodeStatusRow row);
  void post_flush_if_idle();
  void forget_task(const std::string& task_id);

  dds::ServiceContext& ctx_;
  recipe::ValidatorOptions validator_options_;
  Journal journal_;
  dds::Reader<rigger_skill_ExecutorAnnouncement> announcements_;
  dds::Writer<rigger_skill_SkillCommand> commands_;
  dds::Reader<rigger_skill_SkillEvent> events_;
  dds::Reader<rigger_task_Recipe> recipes_;
  dds::Reader<rigger_task_TaskCommand> task_commands_;
  dds::Writer<rigger_task_TaskStatus> task_status_;
  dds::Writer<rigger_task_NodeStatus> node_status_;
  dds::Reader<rigger_task_JournalQuery> journal_queries_;
  dds::Writer<rigger_task_JournalReply> journal_replies_;
  dds::Writer<rigger_operator_ui_OperatorPrompt> prompts_;
  dds::Reader<rigger_operator_ui_OperatorResponse> responses_;
  safety::SafeStopWriter safe_stops_;

  std::map<std::string, Executor> executors_;
  std::map<std::string, std::unique_ptr<Task>> tasks_;
  struct Pending {
    std::string text;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::string, Pending> pending_;  ///< recipes waiting for an executor, by task id
  std::chrono::nanoseconds executor_wait_{};
  std::map<dds_instance_handle_t, std::uint64_t> last_event_seq_;  ///< per executor writer
  std::unique_ptr<world_client::WorldClient> world_;  ///< Condition nodes query the world model through it
  std::chrono::milliseconds condition_timeout_{1000};
  std::uint64_t command_seq_ = 0;

  /// A NodeStatus sample's contents, owned until flush_side_effects() writes it.
  struct NodeStatusRow {
    std::string task_id, node_id, parent_id, node_type, name, code, message, executor_id;
    rigger_task_NodeState state{};
    double progress = -1.0;
    rigger_geometry_Time started{}, finished{}, stamp{};
  };
  std::vector<NodeStatusRow> status_backlog_;
  std::vector<JournalRecord> journal_backlog_;
};

}  // namespace rigger::task_controller
