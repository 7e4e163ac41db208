#pragma once
/// @file
/// The controller's record of a leaf's run and what an executor's event means for it: which run it
/// belongs to (match_run) and what the engine makes of its outcome (to_leaf_event). Pure logic; the
/// wire is rigger::skill_protocol's (controller_endpoint.hpp, leaf_outcome.hpp).

#include <cstdint>
#include <string>

#include "rigger/bt/port.hpp"
#include "rigger/skill_protocol/controller_endpoint.hpp"
#include "rigger/skill_protocol/leaf_outcome.hpp"

namespace rigger::task_controller {

using skill_protocol::ControllerEndpoint;
using skill_protocol::ReceivedEvent;

/// The controller's record of one START it sent: where its commands go (the START's seq is start_seq;
/// the run's events echo it as command_seq) and the engine's activation it answers.
struct LeafRun : skill_protocol::CommandRoute {
  bt::Activation activation = 0;
};

/// How an event relates to the run the controller knows for its node.
enum class RunMatch {
  kCurrent,  ///< from the run's executor and for its current START
  kUnknown,  ///< no run for the node, or another executor's
  kStale,    ///< for an earlier START of the node
};
RunMatch match_run(const LeafRun* run, const std::string& executor_id, std::uint64_t command_seq);

/// An outcome for the engine (kind, code, message, progress; activation not set: the node takes it from
/// its LeafRun). ACCEPTED, PAUSED and RESUMED, which are not the engine's, come out as PROGRESS without a
/// fraction.
bt::LeafEvent to_leaf_event(const skill_protocol::LeafOutcome& outcome);

}  // namespace rigger::task_controller
