#pragma once
/// What the behaviour-tree engine exchanges with the world: the events it consumes, the status it
/// reports, and the Port through which it acts. The engine has no clock, thread or I/O of its
/// own; the controller node (DDS) or a test implements Port.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/bt/tree_spec.hpp"

namespace rigger::bt {

/// The engine's notion of time: monotonic, supplied by Port::now().
using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;
/// Identifies a timer the engine asked the port to schedule. Never reused within one engine.
using TimerId = std::uint64_t;
/// Counts the starts of one node (1 for the first start, 2 after a Retry/Repeat restart …).
/// Commands carry it and events must echo it, so a late event from an earlier run of the same
/// node is recognised as stale.
using Activation = std::uint32_t;

/// States of a node: IDLE → RUNNING → SUCCESS | FAILURE; RUNNING → STOPPING → STOPPED.
enum class NodeState { kIdle, kRunning, kStopping, kSuccess, kFailure, kStopped };
/// "IDLE", "RUNNING", "STOPPING", "SUCCESS", "FAILURE", "STOPPED".
std::string_view to_string(NodeState state);
/// SUCCESS, FAILURE or STOPPED.
bool is_terminal(NodeState state);

/// What a remote leaf (skill or monitor) reports.
enum class LeafEventKind { kSuccess, kFailure, kStopped, kProgress };
std::string_view to_string(LeafEventKind kind);

/// One event from an executor about one leaf.
struct LeafEvent {
  LeafEventKind kind = LeafEventKind::kProgress;
  Activation activation = 0;      ///< the activation of the START this answers
  std::string code;               ///< FAILURE: machine-readable reason ("YANK_DETECTED"); "" otherwise
  std::string message;            ///< for people
  std::optional<double> progress; ///< PROGRESS: fraction done in [0, 1], when the leaf knows it
};

/// Codes the engine itself produces.
namespace codes {
inline constexpr const char* kProtocolError = "PROTOCOL_ERROR";    ///< a monitor reported SUCCESS
inline constexpr const char* kTimeout = "TIMEOUT";                 ///< a Timeout node's deadline passed
inline constexpr const char* kStopTimeout = "STOP_TIMEOUT";        ///< a leaf did not answer SHUTDOWN in time
inline constexpr const char* kFinishedWhileStopping = "FINISHED_WHILE_STOPPING";  ///< SUCCESS/FAILURE raced SHUTDOWN
inline constexpr const char* kConditionFalse = "CONDITION_FALSE";  ///< default code of a false condition
inline constexpr const char* kFailed = "FAILED";                   ///< default code of a FAILURE without one
inline constexpr const char* kInverted = "INVERTED";               ///< an Inverter turned its child's success into failure
inline constexpr const char* kCanceled = "CANCELED";               ///< the task was canceled
inline constexpr const char* kExecutorLost = "EXECUTOR_LOST";      ///< the leaf's executor lost liveliness
/// A running leaf reported STOPPED unasked: its executor ended the run on its own (e.g. it lost the
/// controller, CONTROLLER_LOST) after its safe stop. The leaf no longer acts, so it counts as a failure.
inline constexpr const char* kStoppedByExecutor = "STOPPED_BY_EXECUTOR";
/// A skill's own safe stop failed (its FAILURE code): the engine escalates to a safe stop of its resources.
inline constexpr const char* kSafeStopFailed = "SAFE_STOP_FAILED";
}  // namespace codes

/// Status of one node, reported through Port::node_changed() and Engine::status().
struct NodeStatus {
  NodeIndex index = 0;
  NodeState state = NodeState::kIdle;
  Activation activation = 0;
  std::string code;      ///< failure or stop code, "" on success
  std::string message;   ///< for people
  /// Id of the node where a failure originated (the leaf that failed, or the Timeout/Parallel
  /// that decided); "" while running or after success.
  std::string origin;
  std::optional<double> progress;  ///< last PROGRESS of a remote leaf in this activation
  std::optional<TimePoint> started_at;
  std::optional<TimePoint> finished_at;
  TimePoint changed_at{};
};

/// How the task ended.
enum class TaskOutcome { kSucceeded, kFailed, kCanceled };
std::string_view to_string(TaskOutcome outcome);

/// The task's result (Root = the top node's result, or CANCELED).
struct TaskResult {
  TaskOutcome outcome = TaskOutcome::kFailed;
  std::string code;     ///< "" on success; the originating failure code; "CANCELED"
  std::string message;
  std::string origin;   ///< id of the node where the failure originated, "" on success/cancel
  /// Ids of leaves whose stop timed out and for which a safe stop was escalated.
  std::vector<std::string> escalated;
};

/// What the engine did with an input. Anything but kAccepted/kProtocolError means the input was
/// not acted on; `reason` says why (for the journal and the log).
enum class EventStatus {
  kAccepted,          ///< acted on
  kProtocolError,     ///< acted on as a failure: a monitor reported SUCCESS (the executor is at fault)
  kUnknownNode,       ///< no node with that id
  kWrongKind,         ///< e.g. a leaf event for a Condition, an operator decision for a Skill
  kStaleActivation,   ///< event for an earlier run of the node
  kInvalidActivation, ///< event for a run that was never started
  kNotActive,         ///< node is not running/stopping: a duplicate or late event
  kInvalidArgument,   ///< option out of range, progress outside [0, 1]
  kUnknownTimer,      ///< timer not (or no longer) scheduled by this engine
  kWrongPhase,        ///< start twice, pause while paused, anything after the task finished
  kReentrant,         ///< called from inside a Port callback (queue it and call again afterwards)
};
std::string_view to_string(EventStatus status);

/// Result of every engine input.
struct EventResult {
  EventStatus status = EventStatus::kAccepted;
  std::string reason;  ///< "" when accepted
  bool acted_on() const { return status == EventStatus::kAccepted || status == EventStatus::kProtocolError; }
};

/// The engine's way out. Calls are made synchronously from inside the Engine's input methods;
/// an implementation must not call back into the same Engine from them (it gets kReentrant),
/// it should queue the work. The NodeSpec references are valid for the Engine's lifetime.
class Port {
 public:
  virtual ~Port() = default;

  /// Current monotonic time.
  virtual TimePoint now() = 0;

  /// START a Skill or Monitor: `node.leaf`, `node.params`, `node.executor` ("" = any), `node.kind`.
  virtual void start_leaf(const NodeSpec& node, Activation activation) = 0;
  /// SHUTDOWN a running Skill or Monitor; it must answer STOPPED (or finish) before its stop timeout.
  virtual void shutdown_leaf(const NodeSpec& node, Activation activation, const std::string& reason) = 0;
  /// Evaluate a Condition (`node.leaf`, `node.params`); answer with Engine::on_condition_result().
  virtual void evaluate_condition(const NodeSpec& node, Activation activation) = 0;
  /// Ask the operator `node.prompt` with `node.options`; answer with Engine::on_operator_decision().
  virtual void ask_operator(const NodeSpec& node, Activation activation) = 0;
  /// The question asked by ask_operator() no longer needs an answer (its node was shut down).
  virtual void withdraw_operator_request(const NodeSpec& node, Activation activation) = 0;

  /// Call Engine::on_timer(id) at `deadline` (or as soon after as possible).
  virtual void schedule(TimerId id, TimePoint deadline) = 0;
  /// The timer is no longer needed; calling on_timer(id) anyway is harmless (kUnknownTimer).
  virtual void cancel_timer(TimerId id) = 0;

  /// A leaf did not acknowledge SHUTDOWN within its stop timeout: stop `node.resources` safely by
  /// other means (e.g. robot/crane stop) and record it. The engine treats the leaf as stopped.
  virtual void escalate_safe_stop(const NodeSpec& node, const std::string& why) = 0;

  /// A node's status changed (state, code, progress, or reset to IDLE before a restart).
  virtual void node_changed(const NodeSpec& node, const NodeStatus& status) = 0;
  /// The task finished; called exactly once.
  virtual void finished(const TaskResult& result) = 0;
};

}  // namespace rigger::bt
