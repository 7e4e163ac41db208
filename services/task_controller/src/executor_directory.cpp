#include "executor_directory.hpp"

#include <algorithm>
#include <utility>

#include "rigger/recipe/live_library.hpp"

namespace rigger::task_controller {

ExecutorDirectory::Change ExecutorDirectory::announce(const std::string& id, bool alive,
                                                      const std::string& library_json,
                                                      const std::vector<std::string>& skills,
                                                      std::vector<skill_protocol::AnnouncedRun> runs) {
  Change change;
  auto& ex = executors_[id];
  change.alive = alive;
  change.came_up = alive && !ex.alive;
  change.lost = ex.alive && !alive;
  ex.alive = alive;
  // Text from another process: parsed with bounds (empty: no library announced).
  if (library_json != ex.library_text) {
    ex.library_text = library_json;
    ex.library =
        library_json.empty() ? nlohmann::json() : recipe::parse_announced_library(library_json, &change.library_error);
  }
  ex.skills = std::set<std::string>(skills.begin(), skills.end());
  change.runs_changed = runs != ex.runs;
  ex.runs = std::move(runs);
  return change;
}

bool ExecutorDirectory::gone(const std::string& id) {
  auto it = executors_.find(id);
  if (it == executors_.end()) return false;
  const bool was_alive = it->second.alive;
  it->second.alive = false;
  return was_alive;
}

std::string ExecutorDirectory::pick(const std::string& skill, const std::string& pinned) const {
  if (!pinned.empty()) {
    auto it = executors_.find(pinned);
    return it != executors_.end() && it->second.alive && it->second.skills.count(skill) ? pinned : std::string();
  }
  for (const auto& [id, ex] : executors_)
    if (ex.alive && ex.skills.count(skill)) return id;
  return {};
}

skill::SkillLibrary ExecutorDirectory::live_library(std::vector<std::string>* problems) const {
  std::vector<recipe::AnnouncedLibrary> announced;
  for (const auto& [id, ex] : executors_)
    if (ex.alive && !ex.library.is_null()) announced.push_back({id, &ex.library});
  return recipe::live_library(announced, problems);
}

bool ExecutorDirectory::alive(const std::string& id) const {
  auto it = executors_.find(id);
  return it != executors_.end() && it->second.alive;
}

std::optional<ExecutorDirectory::Holder> ExecutorDirectory::holder(const std::vector<std::string>& resources,
                                                                   const std::string& task_id,
                                                                   const std::set<std::string>* started,
                                                                   const std::string& node_id) const {
  for (const auto& [id, ex] : executors_) {
    if (!ex.alive) continue;  // a lost executor's runs are its leaves' EXECUTOR_LOST, not a hold
    for (const auto& run : ex.runs) {
      if (started != nullptr && !node_id.empty() && run.task_id == task_id && run.node_id == node_id &&
          started->count(node_id) == 0)
        return Holder{id, "", run};
      if (run.task_id == task_id && (started == nullptr || started->count(run.node_id) != 0)) continue;
      for (const auto& r : resources)
        if (std::find(run.resources.begin(), run.resources.end(), r) != run.resources.end()) return Holder{id, r, run};
    }
  }
  return std::nullopt;
}

std::string ExecutorDirectory::Holder::describe() const {
  if (resource.empty())
    return "its own earlier run, " + run.skill + " (task " + run.task_id + ", node " + run.node_id + ") on executor " +
           executor_id + (run.stopping ? ", stopping" : ", running");
  return "resource '" + resource + "', held by " + run.skill + " (task " + run.task_id + ", node " + run.node_id +
         ") on executor " + executor_id + (run.stopping ? ", stopping" : ", running");
}

}  // namespace rigger::task_controller
