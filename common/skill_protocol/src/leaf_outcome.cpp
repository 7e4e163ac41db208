#include "rigger/skill_protocol/leaf_outcome.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::skill_protocol {

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::kSuccess:
      return "SUCCESS";
    case EventKind::kFailure:
      return "FAILURE";
    case EventKind::kStopped:
      return "STOPPED";
    case EventKind::kProgress:
      return "PROGRESS";
    case EventKind::kAccepted:
      return "ACCEPTED";
    case EventKind::kPaused:
      return "PAUSED";
    case EventKind::kResumed:
      return "RESUMED";
  }
  return "?";
}

std::string answer_name(EventKind kind, bool refused) {
  return refused ? std::string("NOT_") + to_string(kind) : std::string(to_string(kind));
}

void to_wire(const LeafOutcome& outcome, rigger_skill_SkillEvent& event) {
  switch (outcome.kind) {
    case EventKind::kSuccess:
      event.kind = rigger_skill_SKILL_EVENT_SUCCESS;
      break;
    case EventKind::kFailure:
      event.kind = rigger_skill_SKILL_EVENT_FAILURE;
      break;
    case EventKind::kStopped:
      event.kind = rigger_skill_SKILL_EVENT_STOPPED;
      break;
    case EventKind::kProgress:
      event.kind = rigger_skill_SKILL_EVENT_PROGRESS;
      break;
    case EventKind::kAccepted:
      event.kind = rigger_skill_SKILL_EVENT_ACCEPTED;
      break;
    case EventKind::kPaused:
      event.kind = rigger_skill_SKILL_EVENT_PAUSED;
      break;
    case EventKind::kResumed:
      event.kind = rigger_skill_SKILL_EVENT_RESUMED;
      break;
  }
  event.code = dds::wire_string(outcome.code);
  event.message = dds::wire_string(outcome.message);
  event.progress = outcome.progress.value_or(-1.0);
}

LeafOutcome from_wire(const rigger_skill_SkillEvent& event) {
  LeafOutcome out;
  out.code = dds::to_string(event.code);
  out.message = dds::to_string(event.message);
  switch (event.kind) {
    case rigger_skill_SKILL_EVENT_SUCCESS:
      out.kind = EventKind::kSuccess;
      break;
    case rigger_skill_SKILL_EVENT_FAILURE:
      out.kind = EventKind::kFailure;
      break;
    case rigger_skill_SKILL_EVENT_STOPPED:
      out.kind = EventKind::kStopped;
      break;
    case rigger_skill_SKILL_EVENT_ACCEPTED:
      out.kind = EventKind::kAccepted;
      break;
    case rigger_skill_SKILL_EVENT_PAUSED:
      out.kind = EventKind::kPaused;
      break;
    case rigger_skill_SKILL_EVENT_RESUMED:
      out.kind = EventKind::kResumed;
      break;
    default:
      out.kind = EventKind::kProgress;
      if (event.progress >= 0.0 && event.progress <= 1.0) out.progress = event.progress;
      break;
  }
  return out;
}

}  // namespace rigger::skill_protocol
