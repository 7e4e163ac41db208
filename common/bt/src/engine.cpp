#include "rigger/bt/engine.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "status_text.hpp"

namespace rigger::bt {

/// Marks the engine busy for one input so that a Port calling back in is refused, not nested.
class Engine::DispatchGuard {
 public:
  explicit DispatchGuard(bool& flag) : flag_(flag) { flag_ = true; }
  ~DispatchGuard() { flag_ = false; }
  DispatchGuard(const DispatchGuard&) = delete;
  DispatchGuard& operator=(const DispatchGuard&) = delete;

 private:
  bool& flag_;
};

Engine::Engine(TreeSpec spec, Port& port) : spec_(std::move(spec)), port_(port) {
  check_tree_spec(spec_);
  parents_ = compute_parents(spec_);
  can_succeed_ = compute_can_succeed(spec_);
  const std::size_t n = spec_.nodes.size();
  status_.resize(n);
  runtime_.resize(n);
  index_of_.reserve(n);
  for (NodeIndex i = 0; i < n; ++i) {
    status_[i].index = i;
    index_of_.emplace(spec_.nodes[i].id, i);
  }
}

std::optional<NodeIndex> Engine::find(std::string_view node_id) const {
  const auto it = index_of_.find(node_id);
  if (it == index_of_.end()) {
    return std::nullopt;
  }
  return it->second;
}

EventResult Engine::reject(EventStatus status, std::string reason) const { return {status, std::move(reason)}; }

// ---------------------------------------------------------------------------------------------
// Inputs

EventResult Engine::start() {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "start() called from inside a Port callback");
  }
  if (started_) {
    return reject(EventStatus::kWrongPhase, result_ ? "task already finished" : "task already started");
  }
  DispatchGuard guard(dispatching_);
  started_ = true;
  request_start(spec_.root);
  drain();
  return {};
}

EventResult Engine::start(const Restoration& restoration) {
  if (restoration.nodes.size() != spec_.nodes.size()) {
    return reject(EventStatus::kInvalidArgument, "restoration has " + std::to_string(restoration.nodes.size()) +
                                                     " nodes, the tree " + std::to_string(spec_.nodes.size()));
  }
  if (dispatching_ || started_) {
    return start();  // the same refusal
  }
  restored_ = restoration.nodes;
  return start();
}

bool Engine::take_restored(NodeIndex index, bool queue) {
  if (restored_.empty()) {
    return false;
  }
  RestoredNode r = std::move(restored_[index]);
  restored_[index] = RestoredNode{};
  NodeStatus& st = status_[index];
  st.activation = std::max(st.activation, r.activations);
  if (r.how == Restored::kRun) {
    // Put back what activate() needs once it reset the runtime.
    restored_[index].cursor = r.cursor;
    restored_[index].chosen = r.chosen;
    restored_[index].how = Restored::kRun;
    return false;
  }
  const TimePoint now = port_.now();
  ++st.activation;
  st.state = r.how == Restored::kSucceeded ? NodeState::kSuccess
             : r.how == Restored::kFailed  ? NodeState::kFailure
                                           : NodeState::kStopped;
  st.code = r.how == Restored::kSucceeded ? std::string() : (r.code.empty() ? std::string(codes::kFailed) : r.code);
  st.message = r.message;
  st.origin = r.how == Restored::kFailed ? spec_.nodes[index].id : std::string();
  st.progress.reset();
  st.started_at = now;
  st.finished_at = now;
  st.changed_at = now;
  runtime_[index] = Runtime{};
  emit(index);
  if (queue) {
    finished_nodes_.push_back(index);
  }
  return true;
}

EventResult Engine::check_node_event(std::string_view node_id, NodeKind expected_a, NodeKind expected_b,
                                     Activation activation, NodeIndex& index) const {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "event delivered from inside a Port callback");
  }
  const auto found = find(node_id);
  if (!found) {
    return reject(EventStatus::kUnknownNode, "no node \"" + std::string(node_id) + "\" in this tree");
  }
  index = *found;
  const NodeSpec& node = spec_.nodes[index];
  if (node.kind != expected_a && node.kind != expected_b) {
    return reject(EventStatus::kWrongKind, "node \"" + node.id + "\" is a " + std::string(to_string(node.kind)));
  }
  const Activation current = status_[index].activation;
  if (activation == 0 || activation > current) {
    return reject(EventStatus::kInvalidActivation, "activation " + std::to_string(activation) + " of node \"" +
                                                       node.id + "\" was never started (current " +
                                                       std::to_string(current) + ")");
  }
  if (activation < current) {
    return reject(EventStatus::kStaleActivation, "event for activation " + std::to_string(activation) +
                                                     " of node \"" + node.id + "\", which is now in activation " +
                                                     std::to_string(current));
  }
  return {};
}

EventResult Engine::on_leaf_event(std::string_view node_id, const LeafEvent& event) {
  NodeIndex i = 0;
  EventResult checked = check_node_event(node_id, NodeKind::kSkill, NodeKind::kMonitor, event.activation, i);
  if (!checked.acted_on()) {
    return checked;
  }
  DispatchGuard guard(dispatching_);
  const NodeSpec& node = spec_.nodes[i];
  NodeStatus& st = status_[i];
  const bool monitor = node.kind == NodeKind::kMonitor;
  const std::string event_name(to_string(event.kind));
  EventResult result;

  if (event.kind == LeafEventKind::kProgress) {
    if (st.state != NodeState::kRunning && st.state != NodeState::kStopping) {
      return reject(EventStatus::kNotActive, "node \"" + node.id + "\" is " + std::string(to_string(st.state)) +
                                                 ": PROGRESS rejected (late)");
    }
    if (event.progress && !(std::isfinite(*event.progress) && *event.progress >= 0.0 && *event.progress <= 1.0)) {
      return reject(EventStatus::kInvalidArgument, "progress must be in [0, 1]");
    }
    st.progress = event.progress;
    if (!event.message.empty()) {
      st.message = event.message;
    }
    st.changed_at = port_.now();
    emit(i);
    return {};
  }

  if (st.state == NodeState::kRunning) {
    switch (event.kind) {
      case LeafEventKind::kSuccess:
        if (monitor) {
          const std::string why = with_detail("monitor reported SUCCESS; monitors never succeed", event.message);
          finish(i, NodeState::kFailure, codes::kProtocolError, why, node.id);
          result = reject(EventStatus::kProtocolError, why);
        } else {
          finish(i, NodeState::kSuccess, "", event.message, "");
        }
        break;
      case LeafEventKind::kFailure:
        if (event.code == codes::kSafeStopFailed) {  // it failed and could not bring its devices to rest
          escalated_.push_back(node.id);
          port_.escalate_safe_stop(node, with_detail("its safe stop failed", event.message));
        }
        finish(i, NodeState::kFailure, event.code.empty() ? codes::kFailed : event.code, event.message, node.id);
        break;
      case LeafEventKind::kStopped:
        // No SHUTDOWN was sent: the executor ended the run on its own. Waiting for another answer would
        // hang the task; the leaf is at rest and no longer acting, which the parent must hear as a failure.
        finish(i, NodeState::kFailure, codes::kStoppedByExecutor,
               with_detail("its executor stopped it without a SHUTDOWN", event.message), node.id);
        break;
      case LeafEventKind::kProgress:
        break;
    }
  } else if (st.state == NodeState::kStopping) {
    if (event.kind == LeafEventKind::kStopped) {
      finish(i, NodeState::kStopped, "", with_detail("stopped", event.message), "");
    } else if (event.kind == LeafEventKind::kFailure && event.code == codes::kSafeStopFailed) {
      // The skill says its safe stop failed: its devices may still move. The supervisor stops them.
      const std::string why = with_detail("its safe stop failed", event.message) + "; safe stop of its resources escalated";
      escalated_.push_back(node.id);
      port_.escalate_safe_stop(node, why);
      finish(i, NodeState::kStopped, codes::kSafeStopFailed, why, "");
    } else {
      // The leaf finished before it saw the SHUTDOWN: it is no longer acting, which is all the
      // shutdown asked for. Its result no longer matters to the parent, which already decided.
      finish(i, NodeState::kStopped, codes::kFinishedWhileStopping,
             with_detail("reported " + event_name + " before acknowledging SHUTDOWN", event.message), "");
      if (monitor && event.kind == LeafEventKind::kSuccess) {
        result = reject(EventStatus::kProtocolError, "monitor reported SUCCESS; monitors never succeed");
      }
    }
  } else {
    std::string reason = "node \"" + node.id + "\" is " + std::string(to_string(st.state)) + ": " + event_name +
                         " rejected (duplicate or late)";
    if (st.state == NodeState::kStopped && st.code == codes::kStopTimeout) {
      reason = "node \"" + node.id + "\": " + event_name +
               " arrived after the stop timeout; a safe stop was already escalated";
    }
    return reject(EventStatus::kNotActive, reason);
  }
  drain();
  return result;
}

EventResult Engine::on_leaf_lost(std::string_view node_id, Activation activation, const std::string& why) {
  NodeIndex i = 0;
  EventResult checked = check_node_event(node_id, NodeKind::kSkill, NodeKind::kMonitor, activation, i);
  if (!checked.acted_on()) {
    return checked;
  }
  const NodeSpec& node = spec_.nodes[i];
  const NodeState state = status_[i].state;
  if (state != NodeState::kRunning && state != NodeState::kStopping) {
    return reject(EventStatus::kNotActive, "node \"" + node.id + "\" is " + std::string(to_string(state)) +
                                               ": loss of its executor no longer matters");
  }
  DispatchGuard guard(dispatching_);
  const std::string message = with_detail("executor lost", why) + "; safe stop of its resources escalated";
  escalated_.push_back(node.id);
  port_.escalate_safe_stop(node, message);
  finish(i, state == NodeState::kRunning ? NodeState::kFailure : NodeState::kStopped, codes::kExecutorLost, message,
         node.id);
  drain();
  return {};
}

EventResult Engine::on_condition_result(std::string_view node_id, Activation activation, bool holds,
                                        const std::string& code, const std::string& message) {
  NodeIndex i = 0;
  EventResult checked = check_node_event(node_id, NodeKind::kCondition, NodeKind::kCondition, activation, i);
  if (!checked.acted_on()) {
    return checked;
  }
  if (status_[i].state != NodeState::kRunning) {
    return reject(EventStatus::kNotActive, "condition \"" + spec_.nodes[i].id + "\" is " +
                                               std::string(to_string(status_[i].state)) +
                                               ": result rejected (duplicate or late)");
  }
  DispatchGuard guard(dispatching_);
  if (holds) {
    finish(i, NodeState::kSuccess, "", message, "");
  } else {
    finish(i, NodeState::kFailure, code.empty() ? codes::kConditionFalse : code, message, spec_.nodes[i].id);
  }
  drain();
  return {};
}

EventResult Engine::on_operator_decision(std::string_view node_id, Activation activation, std::size_t option) {
  NodeIndex i = 0;
  EventResult checked =
      check_node_event(node_id, NodeKind::kOperatorDecision, NodeKind::kOperatorDecision, activation, i);
  if (!checked.acted_on()) {
    return checked;
  }
  const NodeSpec& node = spec_.nodes[i];
  Runtime& rt = runtime_[i];
  if (status_[i].state != NodeState::kRunning || !rt.awaiting_operator) {
    return reject(EventStatus::kNotActive, "decision \"" + node.id + "\" is not waiting for an answer (" +
                                               std::string(to_string(status_[i].state)) + ")");
  }
  if (option >= node.options.size()) {
    return reject(EventStatus::kInvalidArgument, "option " + std::to_string(option) + " out of range: expected 0.." +
                                                     std::to_string(node.options.size() - 1));
  }
  DispatchGuard guard(dispatching_);
  rt.awaiting_operator = false;
  rt.cursor = option;
  rt.active = 1;
  status_[i].message = "operator chose \"" + node.options[option] + "\"";
  status_[i].changed_at = port_.now();
  emit(i);
  request_start(node.children[option]);
  drain();
  return {};
}

EventResult Engine::on_timer(TimerId id) {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "on_timer() called from inside a Port callback");
  }
  const auto it = timers_.find(id);
  if (it == timers_.end()) {
    return reject(EventStatus::kUnknownTimer, "timer " + std::to_string(id) + " is not scheduled (fired or cancelled)");
  }
  const TimerEntry entry = it->second;
  timers_.erase(it);
  Runtime& rt = runtime_[entry.node];
  if (rt.timer == id) {
    rt.timer.reset();
  }
  const NodeSpec& node = spec_.nodes[entry.node];
  const NodeStatus& st = status_[entry.node];
  if (st.activation != entry.activation) {
    return reject(EventStatus::kStaleActivation, "timer of an earlier activation of \"" + node.id + "\"");
  }
  DispatchGuard guard(dispatching_);
  if (entry.purpose == TimerPurpose::kStopTimeout) {
    if (st.state != NodeState::kStopping) {
      return reject(EventStatus::kNotActive, "stop timer of \"" + node.id + "\", which is not stopping");
    }
    const std::string why = "did not acknowledge SHUTDOWN within " + format_seconds(node.stop_timeout) +
                            " s; safe stop of its resources escalated";
    escalated_.push_back(node.id);
    port_.escalate_safe_stop(node, why);
    finish(entry.node, NodeState::kStopped, codes::kStopTimeout, why, node.id);
  } else {
    if (st.state != NodeState::kRunning || rt.decided) {
      return reject(EventStatus::kNotActive, "deadline of \"" + node.id + "\", which is no longer waiting for it");
    }
    decide(entry.node,
           {NodeState::kFailure, codes::kTimeout,
            "child did not finish within " + format_seconds(node.duration) + " s", node.id},
           "timeout after " + format_seconds(node.duration) + " s");
  }
  drain();
  return {};
}

EventResult Engine::cancel(const std::string& reason) {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "cancel() called from inside a Port callback");
  }
  if (result_) {
    return reject(EventStatus::kWrongPhase, "task already finished");
  }
  if (cancel_requested_) {
    return reject(EventStatus::kWrongPhase, "task is already being canceled");
  }
  DispatchGuard guard(dispatching_);
  cancel_requested_ = true;
  cancel_reason_ = reason;
  if (!started_) {
    started_ = true;
    TaskResult result;
    result.outcome = TaskOutcome::kCanceled;
    result.code = codes::kCanceled;
    result.message = reason;
    result_ = result;
    port_.finished(result);
    return {};
  }
  request_shutdown(spec_.root, "task canceled: " + reason);
  drain();
  return {};
}

EventResult Engine::pause() {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "pause() called from inside a Port callback");
  }
  if (result_) {
    return reject(EventStatus::kWrongPhase, "task already finished");
  }
  if (paused_) {
    return reject(EventStatus::kWrongPhase, "task already paused");
  }
  paused_ = true;
  return {};
}

EventResult Engine::resume() {
  if (dispatching_) {
    return reject(EventStatus::kReentrant, "resume() called from inside a Port callback");
  }
  if (!paused_) {
    return reject(EventStatus::kWrongPhase, "task is not paused");
  }
  DispatchGuard guard(dispatching_);
  paused_ = false;
  while (!pending_starts_.empty()) {
    const NodeIndex next = pending_starts_.front();
    pending_starts_.pop_front();
    // A start held back may have been withdrawn since (its parent was shut down).
    if (runtime_[next].start_pending) {
      runtime_[next].start_pending = false;
      activate(next);
    }
  }
  drain();
  return {};
}

}  // namespace rigger::bt
