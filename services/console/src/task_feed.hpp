#pragma once
/// @file
/// The task side of one DDS domain as the console shows it: the controller's task and node statuses and
/// the executors' announcements, read into a ConsoleState (and its EventLog) and a SkillCatalog. The
/// console has one for its cell and, when a rehearsal domain is configured, one for the rehearsal cell
/// (RehearsalLink), so the two trees never mix. Also the one place a recipe is written.
///
/// Thread safety: the take_*() calls and write_recipe() run on the console's loop thread.
#include <array>
#include <functional>
#include <string>

#include "console_state.hpp"
#include "planner.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/types.hpp"

namespace rigger::console {

class TaskFeed {
 public:
  /// Creates the three readers on `participant`. @throws DdsError.
  TaskFeed(const dds::Participant& participant, ConsoleState& state, SkillCatalog& skills);

  /// Called on the loop with each task status taken (task id, state name, stamp in s since the epoch).
  void on_task_status(std::function<void(const std::string&, const std::string&, double)> observer) {
    task_observer_ = std::move(observer);
  }

  /// Takes each reader's samples on `loop` when it holds some (for readers of the loop's participant).
  void attach(dds::EventLoop& loop);
  /// The readers' handles (e.g. for listeners that wake a loop of another participant).
  std::array<dds_entity_t, 3> readers() const;

  void take_task_status();
  /// Node statuses in the order of their stamps (a take groups samples by instance).
  void take_node_status();
  void take_executors();

 private:
  ConsoleState& state_;
  SkillCatalog& skills_;
  std::function<void(const std::string&, const std::string&, double)> task_observer_;
  dds::Reader<rigger_task_TaskStatus> task_status_;
  dds::Reader<rigger_task_NodeStatus> node_status_;
  dds::Reader<rigger_skill_ExecutorAnnouncement> executors_;
};

/// Writes a recipe on rigger/task/recipe with `submitter`; returns the DDS return code.
dds_return_t write_recipe(const dds::Writer<rigger_task_Recipe>& writer, const std::string& task_id,
                          const std::string& recipe_json, const std::string& submitter);

}  // namespace rigger::console
