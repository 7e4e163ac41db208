#include "executor_directory.hpp"

#include "rigger/recipe/live_library.hpp"

namespace rigger::task_controller {

ExecutorDirectory::Change ExecutorDirectory::announce(const std::string& id, bool alive,
                                                      const std::string& library_json,
                                                      const std::vector<std::string>& skills) {
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

}  // namespace rigger::task_controller
