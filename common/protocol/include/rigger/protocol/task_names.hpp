#pragma once
/// @file
/// The names of the task and node states of idl/task.idl, as every tool and page shows them.

#include <string_view>

#include <rigger/idl/types.hpp>

namespace rigger::protocol::task {

/// "ACCEPTED", "RUNNING", … ; "?" for a value the IDL does not define.
inline const char* task_state_name(int state) {
  switch (state) {
    case rigger_task_TASK_ACCEPTED: return "ACCEPTED";
    case rigger_task_TASK_REJECTED: return "REJECTED";
    case rigger_task_TASK_RUNNING: return "RUNNING";
    case rigger_task_TASK_PAUSED: return "PAUSED";
    case rigger_task_TASK_SUCCEEDED: return "SUCCEEDED";
    case rigger_task_TASK_FAILED: return "FAILED";
    case rigger_task_TASK_CANCELED: return "CANCELED";
    default: return "?";
  }
}

/// "IDLE", "RUNNING", "STOPPING", "SUCCESS", "FAILURE", "STOPPED"; "?" for a value the IDL does not define.
inline const char* node_state_name(int state) {
  switch (state) {
    case rigger_task_NODE_IDLE: return "IDLE";
    case rigger_task_NODE_RUNNING: return "RUNNING";
    case rigger_task_NODE_STOPPING: return "STOPPING";
    case rigger_task_NODE_SUCCESS: return "SUCCESS";
    case rigger_task_NODE_FAILURE: return "FAILURE";
    case rigger_task_NODE_STOPPED: return "STOPPED";
    default: return "?";
  }
}

/// True when `name` is the name of node state `state` (a rigger_task_NodeState), e.g. a state read back
/// from a status or a journal line.
inline bool is_node_state(std::string_view name, int state) {
  return name == node_state_name(state);
}

}  // namespace rigger::protocol::task
