#include "console_state.hpp"

#include <set>

#include "cell_feed.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {
// Strings from DDS are not checked for UTF-8: replace what is not, rather than throw in the loop.
std::string line(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }
std::string text(const json& j, const char* key) { return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : ""; }
}  // namespace

void ConsoleState::update_task(const json& task) {
  std::lock_guard lock(mutex_);
  tasks_[text(task, "task_id")] = task;
  log_.append("task", line(task));
}

std::size_t ConsoleState::running_tasks() const {
  static const std::set<std::string> kRunning = {"ACCEPTED", "RUNNING", "PAUSED"};
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [id, task] : tasks_) n += kRunning.count(text(task, "state"));
  return n;
}

void ConsoleState::update_node(const json& node) {
  std::lock_guard lock(mutex_);
  nodes_[text(node, "task_id")][text(node, "node_id")] = node;
  log_.append("node", line(node));
}

void ConsoleState::update_prompt(const json& prompt) {
  std::lock_guard lock(mutex_);
  const std::string id = text(prompt, "prompt_id");
  if (prompt.value("active", false))
    prompts_[id] = prompt;
  else
    prompts_.erase(id);
  log_.append("prompt", line(prompt));
}

void ConsoleState::update_executor(const json& executor) {
  std::lock_guard lock(mutex_);
  const std::string id = text(executor, "executor_id");
  if (executor.value("alive", true))
    executors_[id] = executor;
  else
    executors_.erase(id);
  log_.append("executor", line(executor));
}

void ConsoleState::update_cell(const json& change) {
  std::lock_guard lock(mutex_);
  merge_cell(cell_, change);
  log_.append("cell", line(change));
}

void ConsoleState::update_revision(const json& revision) {
  std::lock_guard lock(mutex_);
  revision_ = revision;
  log_.append("revision", line(revision));
}

json ConsoleState::snapshot(const std::string& task_id) const {
  std::lock_guard lock(mutex_);
  json out = {{"epoch", log_.epoch()}, {"seq", log_.last_seq()}, {"tasks", json::array()},
              {"prompts", json::array()}, {"executors", json::array()}, {"nodes", json::object()}, {"cell", cell_},
              {"revision", revision_}};
  out["id"] = log_.id_of(out["seq"].get<std::uint64_t>());
  for (const auto& [id, t] : tasks_) out["tasks"].push_back(t);
  for (const auto& [id, p] : prompts_) out["prompts"].push_back(p);
  for (const auto& [id, e] : executors_) out["executors"].push_back(e);
  for (const auto& [task, nodes] : nodes_) {
    if (!task_id.empty() && task != task_id) continue;
    json list = json::array();
    for (const auto& [id, n] : nodes) list.push_back(n);
    out["nodes"][task] = std::move(list);
  }
  return out;
}

json ConsoleState::prompt(const std::string& prompt_id) const {
  std::lock_guard lock(mutex_);
  const auto it = prompts_.find(prompt_id);
  return it == prompts_.end() ? json() : it->second;
}

json ConsoleState::task(const std::string& task_id) const {
  std::lock_guard lock(mutex_);
  const auto it = tasks_.find(task_id);
  return it == tasks_.end() ? json() : it->second;
}

}  // namespace rigger::console
