#pragma once
/// The event-driven behaviour-tree engine (docs/behavior-tree.md). Pure C++: no clock, thread, DDS or
/// logger of its own. Inputs are method calls; outputs go through the Port. Nothing polls: the
/// engine does work only inside an input call.
///
/// Semantics in brief (docs/behavior-tree.md has the full text and sequence diagrams):
/// - START goes down, SUCCESS/FAILURE/STOPPED/PROGRESS come up; a node is IDLE → RUNNING →
///   SUCCESS | FAILURE, or RUNNING → STOPPING → STOPPED.
/// - Two-phase shutdown: a parent that decides (or is shut down) sends SHUTDOWN to its active
///   children and reports only after each of them answered STOPPED (or finished) or passed its
///   stop timeout, in which case Port::escalate_safe_stop() is called and the child counts as stopped.
/// - A sibling never starts before its predecessor finished or stopped.
/// - Parallel(M, K) counts only children that can succeed towards M; it fails as soon as M is
///   unreachable; monitors' SUCCESS is a protocol error treated as FAILURE(PROTOCOL_ERROR).
/// - Events that do not fit (unknown node, stale activation, duplicate, out of order) are
///   rejected with a reason and change nothing.
/// - pause(): no node starts until resume(); running nodes keep running, shutdowns proceed.
///
/// Thread safety: none; call from one thread (the controller's event loop).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "rigger/bt/port.hpp"
#include "rigger/bt/tree_spec.hpp"

namespace rigger::bt {

/// How a node is taken up when a task is resumed from its journal (Engine::start(const Restoration&)).
enum class Restored {
  kRun,        ///< runs as usual when its parent reaches it (re-run if it was running at the crash)
  kSucceeded,  ///< done before the crash: reports SUCCESS at once, nothing below it runs
  kFailed,     ///< failed before the crash (its parent had not acted on it): reports FAILURE at once
  kStopped,    ///< was being stopped at the crash: reports STOPPED at once (its executor stopped it)
};

/// One node's restored state; only its first activation after the restart uses it.
struct RestoredNode {
  Restored how = Restored::kRun;
  std::string code;     ///< kFailed, kStopped: the code reported
  std::string message;  ///< what the node reports ("done before the controller restarted", …)
  /// Activations it had before the crash: the first activation now is this + 1, so that events, prompt
  /// ids and journal rows of the killed controller's runs stay recognisably stale.
  Activation activations = 0;
  /// kRun Retry: failed runs of its child so far (they count towards max_attempts); kRun Repeat:
  /// successes so far.
  std::size_t cursor = 0;
  /// kRun OperatorDecision: the option the operator had chosen (its child runs, nobody is asked again).
  std::optional<std::size_t> chosen;
};

/// A whole tree's restored state, indexed like TreeSpec::nodes (an empty vector: start from scratch).
struct Restoration {
  std::vector<RestoredNode> nodes;
};

class Engine {
 public:
  /// Takes the tree and the port (which must outlive the engine). Throws SpecError when the tree
  /// is malformed (see check_tree_spec). Nothing is sent until start().
  Engine(TreeSpec spec, Port& port);
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Starts the top node (deferred while paused). kWrongPhase if already started or finished.
  EventResult start();
  /// Starts a task resumed from its journal: like start(), but each node takes its first activation
  /// from `restoration` (docs/behavior-tree.md "Resume after a crash"). A node restored as done or
  /// failed reports at once without any Port call; a Sequence/Fallback goes on after its finished
  /// children; a Parallel counts its finished children first and starts only the others (none when they
  /// already decide it); Retry/Repeat keep their counts. kInvalidArgument when the sizes differ.
  EventResult start(const Restoration& restoration);

  /// An executor's event about a Skill or Monitor.
  EventResult on_leaf_event(std::string_view node_id, const LeafEvent& event);
  /// The executor running a Skill or Monitor is gone (liveliness lost, hung): its devices may be
  /// in any state, so a safe stop of the leaf's resources is escalated. RUNNING → FAILURE
  /// (EXECUTOR_LOST); STOPPING → STOPPED (EXECUTOR_LOST) without waiting for the stop timeout.
  EventResult on_leaf_lost(std::string_view node_id, Activation activation, const std::string& why);
  /// The world model's answer for a Condition: `holds` → SUCCESS, otherwise FAILURE with `code`
  /// (CONDITION_FALSE when empty).
  EventResult on_condition_result(std::string_view node_id, Activation activation, bool holds,
                                  const std::string& code = "", const std::string& message = "");
  /// The operator's choice for an OperatorDecision: option index into NodeSpec::options.
  EventResult on_operator_decision(std::string_view node_id, Activation activation, std::size_t option);
  /// A timer scheduled through Port::schedule() is due.
  EventResult on_timer(TimerId id);

  /// Shuts the whole tree down; the task finishes CANCELED once everything stopped.
  /// Before start(): finishes CANCELED at once. kWrongPhase when finished or already canceling.
  EventResult cancel(const std::string& reason);
  /// No node starts until resume(). kWrongPhase when already paused or finished.
  EventResult pause();
  /// Starts what pause() held back, in the order it was requested. kWrongPhase when not paused.
  EventResult resume();

  const TreeSpec& spec() const { return spec_; }
  /// Index of the node with that id.
  std::optional<NodeIndex> find(std::string_view node_id) const;
  /// Current status of a node (index < spec().nodes.size()).
  const NodeStatus& status(NodeIndex index) const { return status_[index]; }
  /// Whether each node can succeed (typed counting), indexed like spec().nodes.
  const std::vector<bool>& can_succeed() const { return can_succeed_; }

  bool started() const { return started_; }
  bool paused() const { return paused_; }
  bool canceling() const { return cancel_requested_; }
  /// The task's result once it finished.
  const std::optional<TaskResult>& result() const { return result_; }
  /// Number of timers scheduled and not yet fired or cancelled (for tests and diagnostics).
  std::size_t pending_timers() const { return timers_.size(); }

 private:
  enum class TimerPurpose { kStopTimeout, kDeadline };
  struct TimerEntry {
    NodeIndex node;
    Activation activation;
    TimerPurpose purpose;
  };
  /// A result decided by a composite while it waits for shut-down children to stop.
  struct Decision {
    NodeState state;
    std::string code;
    std::string message;
    std::string origin;
  };
  /// Per-node run-time bookkeeping besides the public status.
  struct Runtime {
    bool start_pending = false;  ///< start requested while paused
    std::size_t cursor = 0;      ///< Sequence/Fallback: current child; Retry: runs so far; Repeat: successes so far; OperatorDecision: chosen option
    std::size_t active = 0;      ///< children RUNNING, STOPPING or waiting to start
    std::size_t successes = 0;   ///< Parallel
    std::size_t failures = 0;    ///< Parallel
    std::size_t possible = 0;    ///< Parallel: children that can succeed and have not finished
    bool awaiting_operator = false;
    std::optional<Decision> decided;
    std::optional<TimerId> timer;  ///< stop timer (leaf) or deadline (Timeout)
  };

  class DispatchGuard;

  EventResult reject(EventStatus status, std::string reason) const;
  EventResult check_node_event(std::string_view node_id, NodeKind expected_a, NodeKind expected_b,
                               Activation activation, NodeIndex& index) const;

  void request_start(NodeIndex index);
  void activate(NodeIndex index);
  /// Consumes `index`'s restored state on its first activation after a resume; true when the node
  /// was restored as finished (it reported at once, queued for its parent unless `queue` is false).
  bool take_restored(NodeIndex index, bool queue);
  void reset_subtree(NodeIndex index);
  void request_shutdown(NodeIndex top, const std::string& reason);
  void finish(NodeIndex index, NodeState state, std::string code, std::string message, std::string origin);
  void decide(NodeIndex index, Decision decision, const std::string& shutdown_reason);
  void child_done(NodeIndex parent, NodeIndex child);
  void on_parallel_child(NodeIndex index, NodeIndex child);
  void finish_task(NodeIndex root);
  void drain();

  void set_state(NodeIndex index, NodeState state);
  void emit(NodeIndex index);
  TimerId schedule(NodeIndex index, TimerPurpose purpose, TimePoint deadline);
  void cancel_node_timer(NodeIndex index);

  TreeSpec spec_;
  Port& port_;
  std::vector<std::optional<NodeIndex>> parents_;
  std::vector<bool> can_succeed_;
  std::unordered_map<std::string_view, NodeIndex> index_of_;
  std::vector<NodeStatus> status_;
  std::vector<Runtime> runtime_;
  std::unordered_map<TimerId, TimerEntry> timers_;
  TimerId next_timer_ = 1;
  std::deque<NodeIndex> finished_nodes_;  ///< nodes that reached a terminal state; parents not yet told
  std::deque<NodeIndex> pending_starts_;  ///< starts held back by pause()
  std::vector<RestoredNode> restored_;    ///< empty unless resumed; entries reset once used
  std::vector<std::string> escalated_;
  std::string cancel_reason_;
  std::optional<TaskResult> result_;
  bool started_ = false;
  bool paused_ = false;
  bool cancel_requested_ = false;
  bool dispatching_ = false;
};

}  // namespace rigger::bt
