#include "rigger/bt/engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace rigger::bt {
namespace {

std::string format_seconds(Seconds s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", s.count());
  return buffer;
}

Clock::duration to_clock(Seconds s) { return std::chrono::duration_cast<Clock::duration>(s); }

std::string with_detail(std::string text, const std::string& detail) {
  if (!detail.empty()) {
    text += ": " + detail;
  }
  return text;
}

}  // namespace

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
        return reject(EventStatus::kOutOfOrder,
                      "node \"" + node.id + "\" reported STOPPED but no SHUTDOWN was sent (it is RUNNING)");
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

// ---------------------------------------------------------------------------------------------
// Tree mechanics

void Engine::request_start(NodeIndex index) {
  if (paused_) {
    runtime_[index].start_pending = true;
    pending_starts_.push_back(index);
    return;
  }
  activate(index);
}

void Engine::reset_subtree(NodeIndex index) {
  // A restarted node's descendants show their previous run until they run again; reset them so
  // status readers see IDLE. Activations are kept: they only grow, so old events stay stale.
  const TimePoint now = port_.now();
  std::vector<NodeIndex> stack(spec_.nodes[index].children.begin(), spec_.nodes[index].children.end());
  while (!stack.empty()) {
    const NodeIndex d = stack.back();
    stack.pop_back();
    NodeStatus& st = status_[d];
    if (st.state != NodeState::kIdle) {
      const Activation activation = st.activation;
      st = NodeStatus{};
      st.index = d;
      st.activation = activation;
      st.changed_at = now;
      emit(d);
    }
    runtime_[d] = Runtime{};
    stack.insert(stack.end(), spec_.nodes[d].children.begin(), spec_.nodes[d].children.end());
  }
}

void Engine::activate(NodeIndex index) {
  if (take_restored(index, true)) {
    return;
  }
  // A resumed node's counts (restored_ keeps them until its first activation; empty otherwise).
  std::size_t restored_cursor = 0;
  std::optional<std::size_t> restored_choice;
  if (!restored_.empty()) {
    restored_cursor = restored_[index].cursor;
    restored_choice = restored_[index].chosen;
    restored_[index] = RestoredNode{};
  }
  const NodeSpec& node = spec_.nodes[index];
  NodeStatus& st = status_[index];
  if (st.activation > 0) {
    reset_subtree(index);
  }
  Runtime& rt = runtime_[index];
  rt = Runtime{};
  const TimePoint now = port_.now();
  ++st.activation;
  st.state = NodeState::kRunning;
  st.code.clear();
  st.message.clear();
  st.origin.clear();
  st.progress.reset();
  st.started_at = now;
  st.finished_at.reset();
  st.changed_at = now;
  emit(index);

  switch (node.kind) {
    case NodeKind::kSkill:
    case NodeKind::kMonitor:
      port_.start_leaf(node, st.activation);
      break;
    case NodeKind::kCondition:
      port_.evaluate_condition(node, st.activation);
      break;
    case NodeKind::kOperatorDecision:
      if (restored_choice && *restored_choice < node.children.size()) {
        // Resumed after the operator had chosen: the choice stands, nobody is asked again.
        rt.cursor = *restored_choice;
        rt.active = 1;
        st.message = "operator chose \"" + node.options[rt.cursor] + "\" before the controller restarted";
        emit(index);
        request_start(node.children[rt.cursor]);
        break;
      }
      rt.awaiting_operator = true;
      port_.ask_operator(node, st.activation);
      break;
    case NodeKind::kSequence:
    case NodeKind::kFallback:
      rt.active = 1;
      request_start(node.children.front());
      break;
    case NodeKind::kParallel: {
      for (const NodeIndex child : node.children) {
        rt.possible += can_succeed_[child] ? 1 : 0;
      }
      // Resumed: the children that finished before the crash count first; only if they do not decide
      // the Parallel are the others started (no START goes out only to be shut down at once).
      // Results first, then the children that were being stopped (by the decision those results made).
      std::vector<NodeIndex> to_start;
      for (const bool stopped : {false, true}) {
        for (const NodeIndex child : node.children) {
          const bool is_stopped = !restored_.empty() && restored_[child].how == Restored::kStopped;
          if (is_stopped != stopped || status_[index].state != NodeState::kRunning) {
            continue;
          }
          if (take_restored(child, false)) {
            on_parallel_child(index, child);
          } else {
            to_start.push_back(child);
          }
        }
      }
      if (status_[index].state != NodeState::kRunning) {
        break;  // decided by the restored results (finished at once: no child was active)
      }
      rt.active = to_start.size();
      for (const NodeIndex child : to_start) {
        request_start(child);
      }
      break;
    }
    case NodeKind::kTimeout:
      rt.timer = schedule(index, TimerPurpose::kDeadline, now + to_clock(node.duration));
      rt.active = 1;
      request_start(node.children.front());
      break;
    case NodeKind::kRetry:
    case NodeKind::kRepeat:
      rt.cursor = restored_cursor;  // runs (Retry) or successes (Repeat) before the crash
      rt.active = 1;
      request_start(node.children.front());
      break;
    case NodeKind::kInverter:
    case NodeKind::kForceSuccess:
      rt.active = 1;
      request_start(node.children.front());
      break;
  }
}

void Engine::request_shutdown(NodeIndex top, const std::string& reason) {
  // Depth-first, parents before children, without recursion: trees built in code may be deep.
  std::vector<NodeIndex> stack{top};
  while (!stack.empty()) {
    const NodeIndex index = stack.back();
    stack.pop_back();
    Runtime& rt = runtime_[index];
    NodeStatus& st = status_[index];
    if (rt.start_pending) {
      // Held back by pause and never started: withdrawing the start is the whole shutdown.
      rt.start_pending = false;
      finished_nodes_.push_back(index);
      continue;
    }
    if (st.state != NodeState::kRunning) {
      continue;  // IDLE, already STOPPING, or finished with its notice queued
    }
    const NodeSpec& node = spec_.nodes[index];
    switch (node.kind) {
      case NodeKind::kSkill:
      case NodeKind::kMonitor:
        set_state(index, NodeState::kStopping);
        st.message = reason;
        emit(index);
        port_.shutdown_leaf(node, st.activation, reason);
        rt.timer = schedule(index, TimerPurpose::kStopTimeout, port_.now() + to_clock(node.stop_timeout));
        continue;
      case NodeKind::kCondition:
        // The controller asked the world model; nothing moves, so it stops at once. A late
        // answer is rejected as not active.
        finish(index, NodeState::kStopped, "", "evaluation abandoned: " + reason, "");
        continue;
      case NodeKind::kOperatorDecision:
        if (rt.awaiting_operator) {
          port_.withdraw_operator_request(node, st.activation);
          finish(index, NodeState::kStopped, "", "question withdrawn: " + reason, "");
          continue;
        }
        break;
      default:
        break;
    }
    // Composites and decorators: a decision they had reached is superseded by the shutdown.
    cancel_node_timer(index);
    rt.decided.reset();
    set_state(index, NodeState::kStopping);
    st.message = reason;
    emit(index);
    if (rt.active == 0) {
      finish(index, NodeState::kStopped, "", reason, "");
      continue;
    }
    stack.insert(stack.end(), node.children.rbegin(), node.children.rend());
  }
}

void Engine::finish(NodeIndex index, NodeState state, std::string code, std::string message, std::string origin) {
  cancel_node_timer(index);
  Runtime& rt = runtime_[index];
  rt.decided.reset();
  rt.awaiting_operator = false;
  NodeStatus& st = status_[index];
  const TimePoint now = port_.now();
  st.state = state;
  st.code = std::move(code);
  st.message = std::move(message);
  st.origin = std::move(origin);
  st.finished_at = now;
  st.changed_at = now;
  emit(index);
  finished_nodes_.push_back(index);
}

void Engine::decide(NodeIndex index, Decision decision, const std::string& shutdown_reason) {
  Runtime& rt = runtime_[index];
  if (rt.active == 0) {
    finish(index, decision.state, std::move(decision.code), std::move(decision.message), std::move(decision.origin));
    return;
  }
  // Two-phase: shut the still-active children down and report only when all of them stopped.
  rt.decided = std::move(decision);
  for (const NodeIndex child : spec_.nodes[index].children) {
    request_shutdown(child, shutdown_reason);
  }
}

void Engine::drain() {
  while (!finished_nodes_.empty()) {
    const NodeIndex done = finished_nodes_.front();
    finished_nodes_.pop_front();
    if (parents_[done]) {
      child_done(*parents_[done], done);
    } else {
      finish_task(done);
    }
  }
}

void Engine::child_done(NodeIndex parent, NodeIndex child) {
  Runtime& rt = runtime_[parent];
  NodeStatus& st = status_[parent];
  if (rt.active > 0) {
    --rt.active;
  }
  if (st.state == NodeState::kStopping) {
    if (rt.active == 0) {
      finish(parent, NodeState::kStopped, "", st.message, "");
    }
    return;
  }
  if (st.state != NodeState::kRunning) {
    return;
  }
  if (rt.decided) {
    if (rt.active == 0) {
      Decision d = std::move(*rt.decided);
      finish(parent, d.state, std::move(d.code), std::move(d.message), std::move(d.origin));
    }
    return;
  }

  const NodeSpec& node = spec_.nodes[parent];
  const NodeStatus& cs = status_[child];
  const bool ok = cs.state == NodeState::kSuccess;
  // Only a shutdown stops a child, and shutdowns come from a stopping or deciding parent
  // (handled above); a STOPPED child here would be a bug, so treat it as a failure.
  const std::string child_code = ok ? "" : (cs.code.empty() ? std::string(codes::kFailed) : cs.code);
  const std::string child_origin = cs.origin.empty() ? spec_.nodes[child].id : cs.origin;
  const std::size_t n = node.children.size();

  switch (node.kind) {
    case NodeKind::kSequence:
      if (!ok) {
        finish(parent, NodeState::kFailure, child_code, cs.message, child_origin);
      } else if (++rt.cursor < n) {
        rt.active = 1;
        request_start(node.children[rt.cursor]);
      } else {
        finish(parent, NodeState::kSuccess, "", "", "");
      }
      break;
    case NodeKind::kFallback:
      if (ok) {
        finish(parent, NodeState::kSuccess, "", "", "");
      } else if (++rt.cursor < n) {
        rt.active = 1;
        request_start(node.children[rt.cursor]);
      } else {
        finish(parent, NodeState::kFailure, child_code,
               with_detail("all " + std::to_string(n) + " alternatives failed; last", cs.message), child_origin);
      }
      break;
    case NodeKind::kParallel:
      on_parallel_child(parent, child);
      break;
    case NodeKind::kInverter:
      if (ok) {
        finish(parent, NodeState::kFailure, codes::kInverted, "child succeeded", node.id);
      } else {
        finish(parent, NodeState::kSuccess, "", "child failed (" + child_code + ")", "");
      }
      break;
    case NodeKind::kForceSuccess:
      finish(parent, NodeState::kSuccess, "", ok ? "" : "child failed (" + child_code + "), success forced", "");
      break;
    case NodeKind::kRetry:
      if (ok) {
        finish(parent, NodeState::kSuccess, "", "", "");
      } else if (++rt.cursor < node.count) {
        rt.active = 1;
        request_start(node.children.front());
      } else {
        finish(parent, NodeState::kFailure, child_code,
               with_detail("failed " + std::to_string(node.count) + " attempt(s); last", cs.message), child_origin);
      }
      break;
    case NodeKind::kRepeat:
      if (!ok) {
        finish(parent, NodeState::kFailure, child_code,
               with_detail("failed in repetition " + std::to_string(rt.cursor + 1), cs.message), child_origin);
      } else if (++rt.cursor < node.count) {
        rt.active = 1;
        request_start(node.children.front());
      } else {
        finish(parent, NodeState::kSuccess, "", "", "");
      }
      break;
    case NodeKind::kTimeout:
    case NodeKind::kOperatorDecision:
      if (ok) {
        finish(parent, NodeState::kSuccess, "", cs.message, "");
      } else {
        finish(parent, NodeState::kFailure, child_code, cs.message, child_origin);
      }
      break;
    case NodeKind::kSkill:
    case NodeKind::kMonitor:
    case NodeKind::kCondition:
      break;  // leaves have no children
  }
}

void Engine::on_parallel_child(NodeIndex index, NodeIndex child) {
  Runtime& rt = runtime_[index];
  const NodeSpec& node = spec_.nodes[index];
  const NodeStatus& cs = status_[child];
  const bool ok = cs.state == NodeState::kSuccess;
  if (ok) {
    ++rt.successes;
  } else {
    ++rt.failures;
  }
  if (can_succeed_[child] && rt.possible > 0) {
    --rt.possible;  // finished either way: it can no longer contribute a future success
  }
  const std::size_t m = node.success_threshold;
  const std::size_t k = node.failure_threshold;
  const std::string counts = std::to_string(rt.successes) + " succeeded, " + std::to_string(rt.failures) +
                             " failed (M=" + std::to_string(m) + ", K=" + std::to_string(k) + ")";
  const std::string child_code = ok ? "" : (cs.code.empty() ? std::string(codes::kFailed) : cs.code);
  const std::string child_origin = cs.origin.empty() ? spec_.nodes[child].id : cs.origin;
  if (rt.successes >= m) {
    decide(index, {NodeState::kSuccess, "", counts, ""}, "parallel succeeded");
  } else if (!ok && rt.failures >= k) {
    decide(index, {NodeState::kFailure, child_code, with_detail(counts, cs.message), child_origin},
           "parallel failed");
  } else if (!ok && rt.successes + rt.possible < m) {
    decide(index,
           {NodeState::kFailure, child_code,
            with_detail(counts + "; success threshold no longer reachable", cs.message), child_origin},
           "parallel failed: success threshold unreachable");
  }
}

void Engine::finish_task(NodeIndex root) {
  const NodeStatus& st = status_[root];
  TaskResult result;
  if (st.state == NodeState::kSuccess) {
    result.outcome = TaskOutcome::kSucceeded;
    result.message = st.message;
  } else if (st.state == NodeState::kFailure) {
    result.outcome = TaskOutcome::kFailed;
    result.code = st.code;
    result.message = st.message;
    result.origin = st.origin;
  } else {
    result.outcome = TaskOutcome::kCanceled;
    result.code = codes::kCanceled;
    result.message = cancel_reason_;
  }
  result.escalated = escalated_;
  result_ = result;
  port_.finished(result);
}

// ---------------------------------------------------------------------------------------------
// Helpers

void Engine::set_state(NodeIndex index, NodeState state) {
  status_[index].state = state;
  status_[index].changed_at = port_.now();
}

void Engine::emit(NodeIndex index) { port_.node_changed(spec_.nodes[index], status_[index]); }

TimerId Engine::schedule(NodeIndex index, TimerPurpose purpose, TimePoint deadline) {
  const TimerId id = next_timer_++;
  timers_.emplace(id, TimerEntry{index, status_[index].activation, purpose});
  port_.schedule(id, deadline);
  return id;
}

void Engine::cancel_node_timer(NodeIndex index) {
  Runtime& rt = runtime_[index];
  if (rt.timer) {
    timers_.erase(*rt.timer);
    port_.cancel_timer(*rt.timer);
    rt.timer.reset();
  }
}

}  // namespace rigger::bt
