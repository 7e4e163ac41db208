// The engine's tree mechanics: what happens inside the tree after an input (engine.cpp) — nodes
// activated, shut down, finished, their parents deciding, the task's end — and the helpers they share.
#include <algorithm>
#include <utility>

#include "rigger/bt/engine.hpp"
#include "status_text.hpp"

namespace rigger::bt {
namespace {

Clock::duration to_clock(Seconds s) { return std::chrono::duration_cast<Clock::duration>(s); }

}  // namespace

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
