#pragma once
/// @file
/// Results for everyone: the controller's writers of rigger/task/status (one sample per task state
/// change, with every recipe error on a rejection) and rigger/task/node_status.

#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/recipe/recipe_validator.hpp"

namespace rigger::task_controller {

/// A NodeStatus sample's contents, owned until it is written (the node queues them while a handler
/// runs and writes them right after it).
struct NodeStatusRow {
  std::string task_id, node_id, parent_id, node_type, name, code, message, executor_id;
  rigger_task_NodeState state{};
  double progress = -1.0;
  rigger_geometry_Time started{}, finished{}, stamp{};
};

class StatusPublisher {
 public:
  /// A rejected hostile recipe may have very many errors; the first ones tell the story.
  static constexpr std::size_t kMaxErrors = 200;

  /// @throws DdsError.
  explicit StatusPublisher(const dds::Participant& participant);
  /// Writes a TaskStatus (`state`: rigger_task_TaskState). Returns false when the write failed.
  bool task(const std::string& task_id, int state, const std::string& code, const std::string& message,
            const std::string& failed_node, const std::vector<recipe::Error>& errors = {});
  bool node(const NodeStatusRow& row);

 private:
  dds::Writer<rigger_task_TaskStatus> task_status_;
  dds::Writer<rigger_task_NodeStatus> node_status_;
};

}  // namespace rigger::task_controller
