#include "executor_directory.hpp"

#include "rigger/recipe/conditions.hpp"

namespace rigger::task_controller {
namespace {

/// The conditions the controller answers itself (through the world model), as a skill library.
const skill::SkillLibrary& controller_conditions() {
  static const skill::SkillLibrary library = skill::SkillLibrary::from_json(recipe::controller_conditions_json());
  return library;
}

}  // namespace

ExecutorDirectory::Change ExecutorDirectory::announce(const std::string& id, bool alive,
                                                      const std::string& library_json,
                                                      const std::vector<std::string>& skills) {
  Change change;
  auto& ex = executors_[id];
  change.alive = alive;
  change.came_up = alive && !ex.alive;
  change.lost = ex.alive && !alive;
  ex.alive = alive;
  try {
    ex.library = nlohmann::json::parse(library_json);
  } catch (const std::exception& e) {
    change.library_error = e.what();
    ex.library = nlohmann::json();
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
  skill::SkillLibrary library;
  for (const auto& [id, ex] : executors_) {
    if (!ex.alive || ex.library.is_null()) continue;
    auto parsed = skill::SkillLibrary::parse(ex.library);
    if (!parsed.value) {
      if (problems)
        problems->push_back("executor library invalid executor=" + id + " errors=" +
                            std::to_string(parsed.errors.size()));
      continue;
    }
    for (const auto& e : library.merge(*parsed.value))
      if (problems) problems->push_back("executor library conflict executor=" + id + " at " + e.pointer + ": " + e.message);
  }
  for (const auto& [name, description] : controller_conditions().descriptions())
    if (library.find(name) == nullptr) library.add(description);
  return library;
}

bool ExecutorDirectory::alive(const std::string& id) const {
  auto it = executors_.find(id);
  return it != executors_.end() && it->second.alive;
}

}  // namespace rigger::task_controller
