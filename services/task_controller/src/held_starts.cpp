// Task's held STARTs: a START waits while a run of another task (or, resumed, of the killed controller)
// holds a resource of its leaf, or while its executor's command reader is not matched yet; it goes out
// when the announcements free it, or fails after busy_wait.
#include <chrono>
#include <set>

#include "rigger/base/text.hpp"
#include "task_port.hpp"

namespace rigger::task_controller {

std::string Task::waits_for(const bt::NodeSpec& spec, bool* unreachable) const {
  if (unreachable) *unreachable = false;
  std::string holder = held_by(spec);
  if (!holder.empty()) return holder;
  const std::string executor_id = host_.pick_executor(spec.leaf, spec.executor);
  if (executor_id.empty() || host_.endpoint().reachable(executor_id)) return {};
  if (unreachable) *unreachable = true;
  return "executor " + executor_id + ", whose command reader this controller has not discovered yet";
}

std::string Task::held_by(const bt::NodeSpec& spec) const {
  if (!resumed_) return host_.holder_of(spec.resources, id_);
  std::set<std::string> started;
  for (const auto& [node_id, run] : runs_) started.insert(node_id);
  return host_.holder_of(spec.resources, id_, &started, spec.id);
}

dds::EventLoop::TimerId Task::arm_held(const std::string& node_id, bt::Activation activation) {
  TaskHost* host = &host_;
  const std::string task_id = id_;
  return host_.loop().after(host_.busy_wait(), [host, task_id, node_id, activation] {
    if (Task* t = host->find_task(task_id)) t->held_too_long(node_id, activation);
  });
}

void Task::start_held() {
  std::vector<std::string> node_ids;
  for (const auto& [node_id, held] : held_) node_ids.push_back(node_id);
  for (const auto& node_id : node_ids) {
    auto h = held_.find(node_id);
    auto index = engine_->find(node_id);
    if (h == held_.end() || !index) continue;
    const auto& spec = engine_->spec().nodes[*index];
    if (h->second.freed) continue;  // free already; waits for RESUME
    const std::string holder = waits_for(spec);
    if (!holder.empty()) {
      h->second.holder = holder;  // perhaps another run now: the failure names the last one
      continue;
    }
    release_held(node_id);
  }
}

void Task::release_held(const std::string& node_id) {
  auto h = held_.find(node_id);
  auto index = engine_->find(node_id);
  if (h == held_.end() || !index) return;
  Held& held = h->second;
  const auto& spec = engine_->spec().nodes[*index];
  if (held.deadline != 0) host_.loop().cancel(held.deadline);
  held.deadline = 0;
  if (engine_->paused()) {
    // The engine counts the leaf as started, but a paused task sends nothing that moves: RESUME sends it.
    if (!held.freed)
      host_.journal({wall_now_s(), id_, node_id, "COMMAND", codes::kStartWaits,
                     spec.leaf + ": its resources are free; the task is paused, so it starts on RESUME"});
    held.freed = true;
    return;
  }
  if (held.freed) {
    // Freed while paused: another run may have taken a resource since; then it waits again.
    held.freed = false;
    const std::string holder = waits_for(spec);
    if (!holder.empty()) {
      held.holder = holder;
      held.deadline = arm_held(node_id, held.activation);
      return;
    }
  }
  const bt::Activation activation = held.activation;
  held_.erase(h);
  send_start(spec, activation);
}

void Task::held_too_long(const std::string& node_id, bt::Activation activation) {
  auto h = held_.find(node_id);
  auto index = engine_->find(node_id);
  if (h == held_.end() || h->second.activation != activation || !index) return;
  const auto& spec = engine_->spec().nodes[*index];
  bool unreachable = false;
  const std::string holder = waits_for(spec, &unreachable);
  if (holder.empty()) {  // freed by the announcement just taken
    h->second.deadline = 0;  // it fired
    release_held(node_id);
    return;
  }
  held_.erase(h);
  const double waited_s = std::chrono::duration<double>(host_.busy_wait()).count();
  host_.log()->error("start held too long task={} node={} holder=\"{}\"", id_, node_id, holder);
  // A START that could never be delivered is one its executor could not answer.
  own_event(node_id, bt::LeafEventKind::kFailure, activation, unreachable ? codes::kStartUnanswered : codes::kResourceHeld,
            spec.leaf + " not started: " + holder + " for " + number_text(waited_s) + " s (busy_wait_s)",
            "resource held");
}

}  // namespace rigger::task_controller
