#pragma once
/// @file
/// The task controller's executor directory: the live executors (rigger/skill/executors, liveliness-
/// monitored), the skills each offers and the runs each holds. Pure logic: the node feeds it the
/// announcements it takes; recipes are validated against live_library(), each leaf is started on
/// pick(), and not before holder() says that no run of another task holds its resources (a restarted
/// controller learns so which runs of its predecessor the executors still run or stop).

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/skill_library.hpp"
#include "rigger/skill_protocol/announced_run.hpp"

namespace rigger::task_controller {

class ExecutorDirectory {
 public:
  /// What one announcement changed.
  struct Change {
    bool alive = false;         ///< the sample says the executor is alive (recipes waiting for one may now pass)
    bool came_up = false;       ///< it was not alive before
    bool lost = false;          ///< it was alive and no longer is
    std::string library_error;  ///< its library_json could not be parsed (it then offers no description)
    bool runs_changed = false;  ///< the runs it holds differ from those it announced before
  };
  /// A run that holds a resource a START needs.
  struct Holder {
    std::string executor_id;
    std::string resource;  ///< the first resource of the START that the run holds
    skill_protocol::AnnouncedRun run;
    /// "resource 'robot', held by Pick (task t1, node root/0) on executor exec, stopping"
    std::string describe() const;
  };

  /// An announcement sample of executor `id`; `alive`: its instance is ALIVE. The library is parsed
  /// when its text differs from the last one announced (executors re-announce every second, mostly
  /// unchanged), so library_error is reported once per text. `runs` replace the runs it held.
  Change announce(const std::string& id, bool alive, const std::string& library_json,
                  const std::vector<std::string>& skills, std::vector<skill_protocol::AnnouncedRun> runs = {});
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

  /// The first run (by executor id, then as announced) on a live executor that holds one of
  /// `resources` and belongs to another task than `task_id` (a run of an earlier controller, or of a
  /// task that ended while its leaf still stopped); nullopt when they are free. Runs of `task_id`
  /// itself are the executors' to order (a Retry's START waits there for the previous run's stop) —
  /// unless `started` is given (a task resumed after a crash): then only its runs of the nodes in
  /// `started` (STARTs this controller sent) are its own, and the killed controller's runs hold; and a
  /// run of `node_id` itself not in `started` holds whatever it claims (a monitor claims nothing): an
  /// executor refuses a START of a node it still runs for a controller it has not yet seen lost.
  std::optional<Holder> holder(const std::vector<std::string>& resources, const std::string& task_id,
                               const std::set<std::string>* started = nullptr, const std::string& node_id = "") const;

 private:
  struct Executor {
    bool alive = false;
    std::string library_text;  ///< as announced; `library` is its parse
    nlohmann::json library;    ///< null when unreadable
    std::set<std::string> skills;
    std::vector<skill_protocol::AnnouncedRun> runs;  ///< as last announced
  };
  std::map<std::string, Executor> executors_;
};

}  // namespace rigger::task_controller
