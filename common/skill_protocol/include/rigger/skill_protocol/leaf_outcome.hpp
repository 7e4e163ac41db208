#pragma once
/// @file
/// What a leaf's run reports, in one domain form on both sides of the skill protocol: the executor
/// endpoint writes it into rigger/skill/event (to_wire), the controller endpoint reads it back
/// (from_wire). Written once here, with its round-trip test; nothing else reads or fills a
/// SkillEvent's kind, code, message and progress.

#include <optional>
#include <string>

#include <rigger/idl/types.hpp>

namespace rigger::skill_protocol {

/// kAccepted, kPaused and kResumed are the executor endpoint's own answers to a START, PAUSE and
/// RESUME; skills report the others.
enum class EventKind { kSuccess, kFailure, kStopped, kProgress, kAccepted, kPaused, kResumed };

/// "SUCCESS", "FAILURE", "STOPPED", "PROGRESS", "ACCEPTED", "PAUSED", "RESUMED" (the wire's names).
const char* to_string(EventKind kind);

/// How the task journal names a leaf's answer to a PAUSE or RESUME (`kind` kPaused or kResumed):
/// to_string(kind) when it did it, "NOT_" + to_string(kind) when it refused (`refused`: a non-empty code).
std::string answer_name(EventKind kind, bool refused);

/// One event of a run: what happened, a machine-readable code (FAILURE's reason, ACCEPTED's WAITING, a
/// refused PAUSE's NOT_PAUSABLE; "" otherwise) and a message for people.
struct LeafOutcome {
  EventKind kind = EventKind::kProgress;
  std::string code;
  std::string message;
  std::optional<double> progress;  ///< kProgress: fraction done in [0, 1], when the leaf knows it
};

/// Fills `event`'s kind, code, message and progress (-1 when unknown). The strings borrow `outcome`'s:
/// write the event while `outcome` lives.
void to_wire(const LeafOutcome& outcome, rigger_skill_SkillEvent& event);
/// The outcome `event` carries. A progress outside [0, 1] (or on another kind) reads as unknown; a kind
/// this build does not know reads as kProgress (it changes nothing in the tree).
LeafOutcome from_wire(const rigger_skill_SkillEvent& event);

}  // namespace rigger::skill_protocol
