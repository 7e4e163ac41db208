#include "leaf_run.hpp"

namespace rigger::task_controller {

RunMatch match_run(const LeafRun* run, const std::string& executor_id, std::uint64_t command_seq) {
  if (run == nullptr || run->executor_id != executor_id) return RunMatch::kUnknown;
  return command_seq == run->start_seq ? RunMatch::kCurrent : RunMatch::kStale;
}

bt::LeafEvent to_leaf_event(const skill_protocol::LeafOutcome& outcome) {
  using skill_protocol::EventKind;
  bt::LeafEvent ev;
  ev.code = outcome.code;
  ev.message = outcome.message;
  switch (outcome.kind) {
    case EventKind::kSuccess:
      ev.kind = bt::LeafEventKind::kSuccess;
      break;
    case EventKind::kFailure:
      ev.kind = bt::LeafEventKind::kFailure;
      break;
    case EventKind::kStopped:
      ev.kind = bt::LeafEventKind::kStopped;
      break;
    case EventKind::kProgress:
      ev.kind = bt::LeafEventKind::kProgress;
      ev.progress = outcome.progress;
      break;
    case EventKind::kAccepted:
    case EventKind::kPaused:
    case EventKind::kResumed:
      ev.kind = bt::LeafEventKind::kProgress;
      break;
  }
  return ev;
}

}  // namespace rigger::task_controller
