#pragma once
/// @file
/// The topics of task (idl/task.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::task {

/// riggerctl, planners → task_controller.
inline constexpr Topic<rigger_task_Recipe> kRecipe{"rigger/task/recipe",
                                                   QosProfile::kCommands,
                                                   "task_id",
                                                   "riggerctl, planners",
                                                   "task_controller",
                                                   "(task_id, recipe JSON text, submitter)",
                                                   ""};

/// riggerctl, UIs → task_controller.
inline constexpr Topic<rigger_task_TaskCommand> kCommand{
    "rigger/task/command", QosProfile::kCommands,     "task_id", "riggerctl, UIs",
    "task_controller",     "(CANCEL, PAUSE, RESUME)", ""};

/// task_controller → all.
inline constexpr Topic<rigger_task_TaskStatus> kStatus{
    "rigger/task/status",
    QosProfile::kState,
    "task_id",
    "task_controller",
    "all",
    "(ACCEPTED, REJECTED with every error as JSON pointer + message, RUNNING, PAUSED, SUCCEEDED, FAILED, CANCELED)",
    ""};

/// task_controller → riggerctl, UIs.
inline constexpr Topic<rigger_task_NodeStatus> kNodeStatus{
    "rigger/task/node_status",
    QosProfile::kState,
    "task_id, node_id",
    "task_controller",
    "riggerctl, UIs",
    "(state, code, message, progress, timestamps)",
    "riggerctl run reads with `state_changes()`: every change, not only the latest"};

/// riggerctl log → task_controller.
inline constexpr Topic<rigger_task_JournalQuery> kJournalQuery{"rigger/task/journal_query",
                                                               QosProfile::kCommands,
                                                               "client_id",
                                                               "riggerctl log",
                                                               "task_controller",
                                                               "(task, max entries; request id)",
                                                               ""};

/// task_controller → riggerctl.
inline constexpr Topic<rigger_task_JournalReply> kJournalReply{"rigger/task/journal_reply",
                                                               QosProfile::kEvents,
                                                               "client_id",
                                                               "task_controller",
                                                               "riggerctl",
                                                               "(the task's timeline from the journal)",
                                                               ""};

}  // namespace rigger::protocol::task
