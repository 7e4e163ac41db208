#include "rigger/bt/port.hpp"

namespace rigger::bt {

std::string_view to_string(NodeState state) {
  switch (state) {
    case NodeState::kIdle:
      return "IDLE";
    case NodeState::kRunning:
      return "RUNNING";
    case NodeState::kStopping:
      return "STOPPING";
    case NodeState::kSuccess:
      return "SUCCESS";
    case NodeState::kFailure:
      return "FAILURE";
    case NodeState::kStopped:
      return "STOPPED";
  }
  return "UNKNOWN";
}

bool is_terminal(NodeState state) {
  return state == NodeState::kSuccess || state == NodeState::kFailure || state == NodeState::kStopped;
}

std::string_view to_string(LeafEventKind kind) {
  switch (kind) {
    case LeafEventKind::kSuccess:
      return "SUCCESS";
    case LeafEventKind::kFailure:
      return "FAILURE";
    case LeafEventKind::kStopped:
      return "STOPPED";
    case LeafEventKind::kProgress:
      return "PROGRESS";
  }
  return "UNKNOWN";
}

std::string_view to_string(TaskOutcome outcome) {
  switch (outcome) {
    case TaskOutcome::kSucceeded:
      return "SUCCEEDED";
    case TaskOutcome::kFailed:
      return "FAILED";
    case TaskOutcome::kCanceled:
      return "CANCELED";
  }
  return "UNKNOWN";
}

std::string_view to_string(EventStatus status) {
  switch (status) {
    case EventStatus::kAccepted:
      return "ACCEPTED";
    case EventStatus::kProtocolError:
      return "PROTOCOL_ERROR";
    case EventStatus::kUnknownNode:
      return "UNKNOWN_NODE";
    case EventStatus::kWrongKind:
      return "WRONG_KIND";
    case EventStatus::kStaleActivation:
      return "STALE_ACTIVATION";
    case EventStatus::kInvalidActivation:
      return "INVALID_ACTIVATION";
    case EventStatus::kNotActive:
      return "NOT_ACTIVE";
    case EventStatus::kInvalidArgument:
      return "INVALID_ARGUMENT";
    case EventStatus::kUnknownTimer:
      return "UNKNOWN_TIMER";
    case EventStatus::kWrongPhase:
      return "WRONG_PHASE";
    case EventStatus::kReentrant:
      return "REENTRANT";
  }
  return "UNKNOWN";
}

}  // namespace rigger::bt
