#pragma once
/// @file
/// The topics of skill executors (idl/skill.idl), each declared once.

#include <string>

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::skill {

/// The partitions of the command topic. The controller writes a leaf's commands in the partition of
/// the leaf's executor once that executor's reader has matched its writer there, so that a command is
/// sent to, and wakes, that executor alone; before that (the first milliseconds after an executor
/// appears) and for anything else it writes in the default partition, which every executor also reads
/// (docs/dds.md#commands-go-to-their-executor-alone).
inline constexpr const char* kCommandPartitionPrefix = "rigger.executor.";
/// What a reader of every command (tests, tools) names besides the default partition.
inline constexpr const char* kCommandPartitionPattern = "rigger.executor.*";
/// The partition that reaches executor `executor_id` alone; "" (none: the default partition only) for
/// an id with a partition wildcard character in it (* ? [ ] \), which would match other executors.
inline std::string command_partition(const std::string& executor_id) {
  if (executor_id.empty() || executor_id.find_first_of("*?[]\\") != std::string::npos) return "";
  return kCommandPartitionPrefix + executor_id;
}

/// task_controller → skill_executor, monitor_host.
inline constexpr Topic<rigger_skill_SkillCommand> kCommand{"rigger/skill/command",
                                                           QosProfile::kCommands,
                                                           "executor_id",
                                                           "task_controller",
                                                           "skill_executor, monitor_host",
                                                           "(START with params JSON / SHUTDOWN with reason / PAUSE / RESUME, seq)",
                                                           "the controller's writer adds MANUAL_BY_PARTICIPANT "
                                                           "liveliness (command_lease_ms, 150 ms): executors shut "
                                                           "down the runs of a controller that lost it "
                                                           "([safety.md](safety.md)); a leaf's commands go in "
                                                           "its executor's partition rigger.executor.<id> "
                                                           "([dds.md](dds.md#commands-go-to-their-executor-alone))"};

/// skill_executor, monitor_host → task_controller.
inline constexpr Topic<rigger_skill_SkillEvent> kEvent{
    "rigger/skill/event",
    QosProfile::kEvents,
    "executor_id",
    "skill_executor, monitor_host",
    "task_controller",
    "(ACCEPTED: the answer to a START, code WAITING when it waits; SUCCESS, FAILURE, STOPPED, PROGRESS; "
    "PAUSED / RESUMED: the answer to a PAUSE / RESUME, code NOT_PAUSABLE when the skill keeps running, NOT_PAUSABLE_STOPPED when it holds a device and is "
    "brought to its safe stop instead; "
    "code, message, seq, command_seq)",
    ""};

/// skill_executor, monitor_host → task_controller, riggerctl.
inline constexpr Topic<rigger_skill_ExecutorAnnouncement> kExecutors{
    "rigger/skill/executors",
    QosProfile::kAnnouncements,
    "executor_id",
    "skill_executor, monitor_host",
    "task_controller, riggerctl",
    "(skills offered with their descriptions as a skill-library JSON document; the runs it holds: task, "
    "node, skill, resources, stopping, re-announced at once when they change)",
    "readers use state(): they request no liveliness lease and see every announcer"};

}  // namespace rigger::protocol::skill
