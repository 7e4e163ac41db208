#include "status_publisher.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::task_controller {

StatusPublisher::StatusPublisher(const dds::Participant& participant)
    : task_status_(participant, protocol::task::kStatus), node_status_(participant, protocol::task::kNodeStatus) {}

bool StatusPublisher::task(const std::string& task_id, int state, const std::string& code, const std::string& message,
                           const std::string& failed_node, const std::vector<recipe::Error>& errors) {
  rigger_task_TaskStatus s{};
  std::vector<rigger_task_RecipeError> wire_errors;
  for (std::size_t i = 0; i < errors.size() && i < kMaxErrors; ++i)
    wire_errors.push_back({dds::wire_string(errors[i].pointer), dds::wire_string(errors[i].message)});
  s.task_id = dds::wire_string(task_id);
  s.state = static_cast<rigger_task_TaskState>(state);
  s.code = dds::wire_string(code);
  s.message = dds::wire_string(message);
  s.failed_node = dds::wire_string(failed_node);
  dds::wire_sequence(s.errors, wire_errors);
  s.stamp = dds::wire_now();
  s.submitted = s.stamp;
  return task_status_.write(s) == DDS_RETCODE_OK;
}

bool StatusPublisher::node(const NodeStatusRow& row) {
  rigger_task_NodeStatus s{};
  s.task_id = dds::wire_string(row.task_id);
  s.node_id = dds::wire_string(row.node_id);
  s.parent_id = dds::wire_string(row.parent_id);
  s.node_type = dds::wire_string(row.node_type);
  s.name = dds::wire_string(row.name);
  s.state = row.state;
  s.code = dds::wire_string(row.code);
  s.message = dds::wire_string(row.message);
  s.progress = row.progress;
  const std::string no_progress_text;  // named: wire_string() keeps a pointer into it until write()
  s.progress_text = dds::wire_string(no_progress_text);
  s.executor_id = dds::wire_string(row.executor_id);
  s.started = row.started;
  s.finished = row.finished;
  s.stamp = row.stamp;
  return node_status_.write(s) == DDS_RETCODE_OK;
}

}  // namespace rigger::task_controller
