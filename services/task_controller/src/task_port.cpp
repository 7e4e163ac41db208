#include "task_port.hpp"

#include <algorithm>
#include <chrono>

#include "rigger/base/text.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/safety/safe_stop.hpp"

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

}  // namespace

Task::Task(TaskHost& host, recipe::ValidatedRecipe recipe, std::string id)
    : host_(host), id_(std::move(id)), resources_(recipe.resources) {
  engine_ = std::make_unique<bt::Engine>(std::move(recipe.tree), *this);
  // A START's parameters never change while the task runs: serialise them here, off the reaction path.
  const auto& nodes = engine_->spec().nodes;
  params_text_.reserve(nodes.size());
  for (const auto& node : nodes)
    params_text_.push_back(bt::is_remote_leaf(node.kind) ? node.params.dump() : std::string());
}

Task::~Task() {
  for (const auto& [engine_timer, loop_timer] : timers_) host_.loop().cancel(loop_timer);
  for (const auto& [node_id, loop_timer] : unanswered_) host_.loop().cancel(loop_timer);
  for (const auto& [node_id, loop_timer] : resends_) host_.loop().cancel(loop_timer);
  for (const auto& [node_id, held] : held_)
    if (held.deadline != 0) host_.loop().cancel(held.deadline);
}

void Task::defer(std::function<void(Task&)> fn) {
  TaskHost* host = &host_;
  std::string id = id_;
  host_.loop().post([host, id, fn = std::move(fn)] {
    if (Task* t = host->find_task(id)) fn(*t);
  });
}

const std::string& Task::params_text(const bt::NodeSpec& spec) const {
  // The engine hands out references into its own spec; the index follows from the address.
  const auto& nodes = engine_->spec().nodes;
  return params_text_[static_cast<std::size_t>(&spec - nodes.data())];
}

void Task::log_result(const char* what, const std::string& node_id, const bt::EventResult& r) {
  if (r.acted_on()) return;
  host_.log()->warn("{} rejected task={} node={} status={} reason={}", what, id_, node_id, bt::to_string(r.status),
                    r.reason);
  host_.journal({wall_now_s(), id_, node_id, "REJECTED_EVENT", std::string(bt::to_string(r.status)), r.reason});
}

// --- what arrives for the task ---

void Task::on_event(const ReceivedEvent& e) {
  using skill_protocol::EventKind;
  const skill_protocol::LeafOutcome& outcome = e.outcome;
  if (outcome.kind == EventKind::kPaused || outcome.kind == EventKind::kResumed) {
    // What a leaf did with a PAUSE / RESUME: for people (the journal), never for the engine.
    const std::string& code = outcome.code;
    host_.log()->info("{} task={} node={} executor={} code={} {}", skill_protocol::to_string(outcome.kind), id_,
                      e.node_id, e.executor_id, code, outcome.message);
    host_.journal({wall_now_s(), id_, e.node_id, "EVENT", skill_protocol::answer_name(outcome.kind, !code.empty()),
                   code.empty() ? outcome.message : code + ": " + outcome.message});
    return;
  }
  auto run_it = runs_.find(e.node_id);
  const LeafRun* run = run_it == runs_.end() ? nullptr : &run_it->second;
  switch (match_run(run, e.executor_id, e.command_seq)) {
    case RunMatch::kUnknown:
      host_.log()->warn("event rejected (unknown node or executor) executor={} task={} node={}", e.executor_id, id_,
                        e.node_id);
      host_.journal({wall_now_s(), id_, e.node_id, "REJECTED_EVENT", "UNKNOWN", "from " + e.executor_id});
      return;
    case RunMatch::kStale:
      host_.log()->warn("event rejected (stale) executor={} task={} node={} command_seq={} current={}", e.executor_id,
                        id_, e.node_id, e.command_seq, run->start_seq);
      host_.journal({wall_now_s(), id_, e.node_id, "REJECTED_EVENT", "STALE",
                     "command_seq " + std::to_string(e.command_seq) + " is not the current START " +
                         std::to_string(run->start_seq)});
      return;
    case RunMatch::kCurrent: break;
  }
  // Any event of the current run answers its START: neither its answer timer nor its resend wakes the
  // loop later (one wake-up per START otherwise, start_resend_s after it, for nothing).
  if (auto u = unanswered_.find(e.node_id); u != unanswered_.end()) {
    host_.loop().cancel(u->second);
    unanswered_.erase(u);
  }
  if (auto r = resends_.find(e.node_id); r != resends_.end()) {
    host_.loop().cancel(r->second);
    resends_.erase(r);
  }
  if (outcome.kind == EventKind::kAccepted) {
    // Running needs no row (its events follow); a START that waits does: it explains the delay.
    if (!outcome.code.empty())
      host_.journal({wall_now_s(), id_, e.node_id, "EVENT", skill_protocol::to_string(outcome.kind),
                     outcome.code + ": " + outcome.message});
    return;
  }
  bt::LeafEvent ev = to_leaf_event(outcome);
  ev.activation = run->activation;
  if (ev.kind == bt::LeafEventKind::kProgress) {
    journal_progress(e.node_id, ev);
  } else {
    end_progress(e.node_id);
    host_.journal({wall_now_s(), id_, e.node_id, "EVENT", std::string(bt::to_string(ev.kind)),
                   ev.code.empty() ? ev.message : ev.code + ": " + ev.message});
  }
  log_result("event", e.node_id, engine_->on_leaf_event(e.node_id, ev));
}

void Task::executor_lost(const std::string& executor_id) {
  std::vector<std::pair<std::string, bt::Activation>> hit;
  for (const auto& [node_id, run] : runs_)
    if (run.executor_id == executor_id) hit.emplace_back(node_id, run.activation);
  for (const auto& [node_id, activation] : hit) {
    auto index = engine_->find(node_id);
    if (!index) continue;
    const auto& st = engine_->status(*index);
    if (st.activation != activation || (st.state != NodeState::kRunning && st.state != NodeState::kStopping))
      continue;
    end_progress(node_id);
    log_result("executor lost", node_id,
               engine_->on_leaf_lost(node_id, activation, "executor " + executor_id + " lost liveliness"));
    if (done()) break;
  }
}

int Task::command(rigger_task_TaskCommandKind kind, const std::string& reason, const std::string& issuer) {
  bt::EventResult r;
  const char* what = "cancel";
  int publish = -1;
  // Who did it: the node's default reason already names the issuer ("requested by <issuer>").
  const std::string who = issuer.empty() ? std::string("an unnamed issuer") : issuer;
  const std::string by = !issuer.empty() && reason.find(issuer) != std::string::npos ? reason : "by " + who + ": " + reason;
  if (kind == rigger_task_TASK_CANCEL) {
    host_.journal({wall_now_s(), id_, "", "COMMAND", "CANCEL", reason});
    r = engine_->cancel(reason);
  } else if (kind == rigger_task_TASK_PAUSE) {
    what = "pause";
    host_.journal({wall_now_s(), id_, "", "COMMAND", "PAUSE", by});
    r = engine_->pause();
    if (r.acted_on()) {
      publish = rigger_task_TASK_PAUSED;
      pause_leaves(true, reason);
    }
  } else {
    what = "resume";
    host_.journal({wall_now_s(), id_, "", "COMMAND", "RESUME", by});
    if (engine_->paused()) pause_leaves(false, reason);
    r = engine_->resume();
    if (r.acted_on()) publish = rigger_task_TASK_RUNNING;
    // The starts whose resources were freed while paused go out now (the engine's own held-back starts
    // went out inside resume()).
    std::vector<std::string> freed;
    for (const auto& [node_id, held] : held_)
      if (held.freed) freed.push_back(node_id);
    for (const auto& node_id : freed) release_held(node_id);
  }
  log_result(what, "", r);
  return publish;
}

void Task::pause_leaves(bool pause, const std::string& why) {
  std::vector<std::pair<std::string, bt::Activation>> leaves;
  if (pause) {
    for (const auto& [node_id, run] : runs_) leaves.emplace_back(node_id, run.activation);
  } else {
    leaves.assign(paused_.begin(), paused_.end());
    paused_.clear();
  }
  const char* command = pause ? "PAUSE" : "RESUME";
  for (const auto& [node_id, activation] : leaves) {
    auto index = engine_->find(node_id);
    auto run = runs_.find(node_id);
    if (!index || run == runs_.end() || run->second.activation != activation) continue;
    const auto& st = engine_->status(*index);
    // A leaf being stopped goes on to its safe stop; one that ended has nothing to hold.
    if (st.activation != activation || st.state != NodeState::kRunning) continue;
    const auto& spec = engine_->spec().nodes[*index];
    LeafRun sent = run->second;
    sent.start_seq = host_.endpoint().next_seq();
    host_.journal({wall_now_s(), id_, node_id, "COMMAND", command, spec.leaf + " on " + sent.executor_id + ": " + why});
    if (!host_.endpoint().send(pause ? rigger_skill_SKILL_PAUSE : rigger_skill_SKILL_RESUME, id_, spec.id, spec.leaf,
                               sent, "{}", why))
      host_.log()->error("skill command write failed task={} node={} kind={}", id_, node_id, command);
    if (pause) paused_[node_id] = activation;
  }
}

void Task::answer(const PromptId& id, const std::string& answer, const std::string& by) {
  const std::string prompt_id = id.str();
  auto p = prompts_.find(prompt_id);
  if (p == prompts_.end()) return;
  const auto [node_id, activation] = p->second;
  auto index = engine_->find(node_id);
  if (!index) return;
  const auto& spec = engine_->spec().nodes[*index];
  const auto choice = option_index(spec.options, answer);
  if (!choice) {
    const std::string expected = quoted_options(spec.options);
    host_.log()->warn("operator answer not an option prompt={} answer={} expected={}", prompt_id, answer, expected);
    host_.journal({wall_now_s(), id_, node_id, "REJECTED_EVENT", "NOT_AN_OPTION",
                   "answer \"" + answer + "\" by " + by + ": expected one of " + expected});
    return;
  }
  prompts_.erase(p);
  host_.journal({wall_now_s(), id_, node_id, "OPERATOR", "ANSWER", answer + " by " + by});
  // The question is settled: withdraw it so that no operator UI keeps showing it.
  host_.prompts().write(id, spec, false);
  log_result("operator decision", node_id, engine_->on_operator_decision(node_id, activation, *choice));
}

// --- bt::Port ---

void Task::shutdown_leaf(const bt::NodeSpec& spec, bt::Activation activation, const std::string& reason) {
  if (auto h = held_.find(spec.id); h != held_.end() && h->second.activation == activation) {
    // Never sent: nothing runs, so the leaf is stopped at once (on a later turn: this is a Port call).
    if (h->second.deadline != 0) host_.loop().cancel(h->second.deadline);
    const std::string why = spec.leaf + " was never started: it waited for " + h->second.holder + " (" + reason + ")";
    held_.erase(h);
    const std::string node_id = spec.id;
    defer([node_id, activation, why](Task& t) {
      t.own_event(node_id, bt::LeafEventKind::kStopped, activation, codes::kNotStarted, why, "held start stopped");
    });
    return;
  }
  auto it = runs_.find(spec.id);
  if (it == runs_.end() || it->second.activation != activation) return;  // never sent: nothing to stop
  send_shutdown(spec, it->second, reason);
}

void Task::send_shutdown(const bt::NodeSpec& spec, const LeafRun& run, const std::string& reason) {
  LeafRun shutdown = run;
  shutdown.start_seq = host_.endpoint().next_seq();
  host_.journal({wall_now_s(), id_, spec.id, "COMMAND", "SHUTDOWN", reason});
  if (!host_.endpoint().send(rigger_skill_SKILL_SHUTDOWN, id_, spec.id, spec.leaf, shutdown, "{}", reason))
    host_.log()->error("skill command write failed task={} node={}", id_, spec.id);
}

void Task::own_event(const std::string& node_id, bt::LeafEventKind kind, bt::Activation activation,
                     const std::string& code, const std::string& message, const char* what) {
  bt::LeafEvent event;
  event.kind = kind;
  event.activation = activation;
  event.code = code;
  event.message = message;
  host_.journal({wall_now_s(), id_, node_id, "EVENT", std::string(bt::to_string(kind)), code + ": " + message});
  log_result(what, node_id, engine_->on_leaf_event(node_id, event));
}

void Task::evaluate_condition(const bt::NodeSpec& spec, bt::Activation activation) {
  TaskHost* host = &host_;
  const std::string task_id = id_, node_id = spec.id, leaf = spec.leaf;
  // The answer always arrives on a later loop turn (WorldClient never calls back inside the call).
  auto answer = [host, task_id, node_id, activation](bool holds, const std::string& code, const std::string& message) {
    Task* t = host->find_task(task_id);
    if (t == nullptr) return;
    t->log_result("condition", node_id, t->engine().on_condition_result(node_id, activation, holds, code, message));
  };
  if (leaf == "ObjectLocalized") {
    const std::string object = spec.params.value("object", std::string());
    const double max_age_s = spec.params.value("max_age_s", 5.0);
    host_.is_localized(object, max_age_s, [answer, object, max_age_s](const world_client::Reply& r) {
      const std::string what = "ObjectLocalized(" + object + ", max_age_s " + number_text(max_age_s) + ")";
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

void Task::ask_operator(const bt::NodeSpec& spec, bt::Activation activation) {
  const PromptId prompt{id_, spec.id, activation};
  prompts_[prompt.str()] = {spec.id, activation};
  host_.prompts().write(prompt, spec, true);
  host_.journal({wall_now_s(), id_, spec.id, "OPERATOR", "ASK", spec.prompt});
}

void Task::withdraw_operator_request(const bt::NodeSpec& spec, bt::Activation activation) {
  const PromptId prompt{id_, spec.id, activation};
  prompts_.erase(prompt.str());
  host_.prompts().write(prompt, spec, false);
}

void Task::schedule(bt::TimerId id, bt::TimePoint deadline) {
  const auto delay = std::max(bt::Clock::duration::zero(), deadline - bt::Clock::now());
  TaskHost* host = &host_;
  std::string task_id = id_;
  timers_[id] = host_.loop().after(std::chrono::duration_cast<std::chrono::nanoseconds>(delay), [host, task_id, id] {
    Task* t = host->find_task(task_id);
    if (t == nullptr) return;
    t->timers_.erase(id);
    t->engine().on_timer(id);
  });
}

void Task::cancel_timer(bt::TimerId id) {
  auto it = timers_.find(id);
  if (it == timers_.end()) return;
  host_.loop().cancel(it->second);
  timers_.erase(it);
}

void Task::escalate_safe_stop(const bt::NodeSpec& spec, const std::string& why) {
  // The devices of every resource the leaf held that a safe stop can name stop and stay stopped
  // until a person resets them (riggerctl estop --reset RESOURCE); the others are logged.
  std::string resources, stopped;
  const auto& stoppable = safety::stoppable_resources();
  for (const auto& r : spec.resources) {
    resources += (resources.empty() ? "" : ",") + r;
    if (std::find(stoppable.begin(), stoppable.end(), r) == stoppable.end()) continue;
    if (!host_.safe_stop(r, "task " + id_ + ", node " + spec.id + ": " + why))
      host_.log()->error("safe stop write failed resource={} task={} node={}", r, id_, spec.id);
    stopped += (stopped.empty() ? "" : ",") + r;
  }
  host_.log()->error("safe stop escalated task={} node={} resources=[{}] stopped=[{}] why={}", id_, spec.id, resources,
                     stopped, why);
  host_.journal({wall_now_s(), id_, spec.id, "ESCALATION", "SAFE_STOP",
                 "resources [" + resources + "], safe stop commanded for [" + stopped + "]: " + why});
}

void Task::node_changed(const bt::NodeSpec& spec, const bt::NodeStatus& status) {
  NodeStatusRow row;
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
  host_.node_status(std::move(row));
  if (status.state != NodeState::kRunning || !status.progress)  // progress lines are not worth a row each
    host_.journal({wall_now_s(), id_, spec.id, "NODE", std::string(bt::to_string(status.state)),
                   status.code.empty() ? status.message : status.code + ": " + status.message});
  if (status.state == NodeState::kSuccess)
    if (const auto l = localizing_.find(spec.id); l != localizing_.end()) {
      // After the commands this SUCCESS causes (the next leaf's START): the world query is not on their path.
      TaskHost* host = &host_;
      host_.loop().post([host, task_id = id_, node_id = spec.id, object = l->second] {
        host->localized(task_id, node_id, object);
      });
    }
}

void Task::finished(const bt::TaskResult& result) {
  // Runs whose end never came (their stop timed out) still count what they left out.
  std::vector<std::string> counted;
  for (const auto& [node_id, rows] : progress_rows_) counted.push_back(node_id);
  for (const auto& node_id : counted) end_progress(node_id);
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
  host_.task_finished(id_, state, journal_state, result, message);
}

void Task::journal_progress(const std::string& node_id, const bt::LeafEvent& event) {
  auto& rows = progress_rows_[node_id];
  if (rows.journaled >= host_.progress_rows_per_run()) {
    ++rows.left_out;
    return;
  }
  ++rows.journaled;
  std::string text = event.progress ? number_text(*event.progress) : std::string();
  if (!event.message.empty()) text += (text.empty() ? "" : ": ") + event.message;
  host_.journal({wall_now_s(), id_, node_id, "EVENT", std::string(bt::to_string(event.kind)), text});
}

void Task::end_progress(const std::string& node_id) {
  auto it = progress_rows_.find(node_id);
  if (it == progress_rows_.end()) return;
  const unsigned left_out = it->second.left_out;
  progress_rows_.erase(it);
  if (left_out == 0) return;
  host_.journal({wall_now_s(), id_, node_id, "EVENT", codes::kProgressLeftOut,
                 std::to_string(left_out) +
                     " more PROGRESS events of this run not journaled (journal_progress_per_run " +
                     std::to_string(host_.progress_rows_per_run()) + ")"});
}

}  // namespace rigger::task_controller
