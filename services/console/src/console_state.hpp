#pragma once
/// @file
/// What the console knows of the cell, in domain form (JSON objects as the browser gets them): every
/// task's last status, every node's last status per task, the open operator prompts and the live
/// executors. Each change is also appended to the EventLog under the same lock, so a snapshot's
/// `seq` is exactly the last event it contains: a client that loads the snapshot and then follows the
/// stream from `seq` misses nothing and sees nothing twice.
///
/// Thread safety: every method may be called from any thread (the DDS loop writes, HTTP threads read).
#include <map>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include "event_log.hpp"

namespace rigger::console {

class ConsoleState {
 public:
  explicit ConsoleState(EventLog& log) : log_(log) {}

  /// A task status: {"task_id", "state", "code", "message", ...}.
  void update_task(const nlohmann::json& task);
  /// A node status: {"task_id", "node_id", "state", ...}.
  void update_node(const nlohmann::json& node);
  /// A prompt: {"prompt_id", "active", ...}; an inactive one is removed from the open prompts.
  void update_prompt(const nlohmann::json& prompt);
  /// An executor's announcement {"executor_id", ...}, or its departure ({"executor_id", "alive": false}).
  void update_executor(const nlohmann::json& executor);
  /// A change of where things are in the cell (cell_feed.hpp): merged into the picture, and sent as a
  /// "cell" event.
  void update_cell(const nlohmann::json& change);
  /// The cell's running revision {"cell_revision", "previous_revision", "who", "comment", "stamp",
  /// "changes"} (rigger/world/cell): kept, and sent as a "revision" event.
  void update_revision(const nlohmann::json& revision);

  /// {"epoch", "seq", "tasks": [...], "prompts": [...], "executors": [...], "nodes": {task: [...]},
  /// "cell": {the picture of cell_feed.hpp}, "revision": {the running revision} or null}; with
  /// a non-empty `task_id` only that task's nodes.
  nlohmann::json snapshot(const std::string& task_id = "") const;
  /// The open prompt `prompt_id`, or null.
  nlohmann::json prompt(const std::string& prompt_id) const;
  /// The last status of task `task_id`, or null.
  nlohmann::json task(const std::string& task_id) const;
  /// How many tasks run: their last state is ACCEPTED, RUNNING or PAUSED.
  std::size_t running_tasks() const;

 private:
  EventLog& log_;
  mutable std::mutex mutex_;
  std::map<std::string, nlohmann::json> tasks_;
  std::map<std::string, std::map<std::string, nlohmann::json>> nodes_;
  std::map<std::string, nlohmann::json> prompts_;
  std::map<std::string, nlohmann::json> executors_;
  nlohmann::json cell_ = nlohmann::json::object();
  nlohmann::json revision_;
};

}  // namespace rigger::console
