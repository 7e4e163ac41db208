#pragma once
/// @file
/// The task controller's executor directory: the live executors (rigger/skill/executors, liveliness-
/// monitored) and the skills each offers. Pure logic: the node feeds it the announcements it takes;
/// recipes are validated against live_library() and each leaf is started on pick().

#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/skill_library.hpp"

namespace rigger::task_controller {

class ExecutorDirectory {
 public:
  /// What one announcement changed.
  struct Change {
    bool alive = false;         ///< the sample says the executor is alive (recipes waiting for one may now pass)
    bool came_up = false;       ///< it was not alive before
    bool lost = false;          ///< it was alive and no longer is
    std::string library_error;  ///< its library_json could not be parsed (it then offers no description)
  };

  /// An announcement sample of executor `id`; `alive`: its instance is ALIVE. The library is parsed
  /// when its text differs from the last one announced (executors re-announce every second, mostly
  /// unchanged), so library_error is reported once per text.
  Change announce(const std::string& id, bool alive, const std::string& library_json,
                  const std::vector<std::string>& skills);
  /// The instance of `id` is no longer alive (disposed, or its writer lost liveliness). Returns whether
  /// it was alive until now (lost now).
  bool gone(const std::string& id);

  /// The live executor that runs `skill`: `pinned` when set (and alive and offering it), else the first
  /// live one offering it by id; "" when none.
  std::string pick(const std::string& skill, const std::string& pinned) const;

  /// The libraries of the live executors merged, plus the conditions the controller evaluates itself
  /// (an executor announcing one of those as well keeps its description). An invalid library is
  /// skipped and a conflicting description left out; each such problem is appended to `problems`.
  skill::SkillLibrary live_library(std::vector<std::string>* problems = nullptr) const;

  bool alive(const std::string& id) const;

 private:
  struct Executor {
    bool alive = false;
    std::string library_text;  ///< as announced; `library` is its parse
    nlohmann::json library;    ///< null when unreadable
    std::set<std::string> skills;
  };
  std::map<std::string, Executor> executors_;
};

}  // namespace rigger::task_controller
