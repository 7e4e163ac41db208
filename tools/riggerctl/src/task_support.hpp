#pragma once
/// @file
/// What riggerctl's task commands share (registered in task_commands.cpp, one file per verb or family):
/// exit codes, the wire's task states and stamps, a node's line in a printed tree, and the client of the
/// task controller's journal. Not thread-safe: each command runs on its one thread.

#include <cstdint>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/task.hpp"

namespace rigger::ctl::tasks {

constexpr int kExitFailed = 1;
constexpr int kExitNoController = 3;

/// Whether a TaskState ends the task (REJECTED, SUCCEEDED, FAILED, CANCELED).
bool task_terminal(int s);

/// A wire time in nanoseconds since the Unix epoch.
std::int64_t wire_ns(const rigger_geometry_Time& t);

/// A wire time as UTC "hh:mm:ss.mmm".
std::string format_wall(const rigger_geometry_Time& t);

/// A node's line in the live tree, indented by depth.
struct NodeLine {
  std::string type, name, state, code, message, executor;
  double progress = -1;
};

/// The printed line of node `id` (indented by its depth in the id's path).
std::string node_line(const std::string& id, const NodeLine& n);

/// A node status as a NodeLine.
NodeLine to_line(const rigger_task_NodeStatus& s);

/// One journal line as the controller sent it.
struct JournalLine {
  rigger_geometry_Time stamp{};
  std::string node_id, kind, code, message;
};

/// The controller's answer to a journal query: ok, or the controller's reason in `message`.
struct JournalAnswer {
  bool answered = false;  ///< false: no controller matched or answered within the timeout
  bool ok = false;
  std::string message;
  std::vector<JournalLine> lines;
};

/// The journal's query writer and reply reader; declare it before the EventLoop that asks through it.
struct JournalTopics {
  explicit JournalTopics(dds::Participant& participant)
      : queries(participant, protocol::task::kJournalQuery), replies(participant, protocol::task::kJournalReply) {}
  dds::Writer<rigger_task_JournalQuery> queries;
  dds::Reader<rigger_task_JournalReply> replies;
};

/// Asks the controller's journal for `task_id`'s timeline ("" : the task list) and waits for the answer.
/// A second question of the same run takes a new `request_id` (late copies of an earlier answer are
/// then told apart).
JournalAnswer ask_journal(JournalTopics& topics, dds::EventLoop& loop, const std::string& task_id, double timeout_s,
                          std::uint64_t request_id = 1);

/// When `answer` is unusable: prints why — no controller answered, or the controller's reason headed
/// by `refusal` ("" for the reason alone) — and returns the exit code; 0 when it is usable.
int journal_failure(const JournalAnswer& answer, const CommonOptions& common, double timeout_s,
                    const std::string& refusal);

// The verbs; each prints its result and returns the exit code.

/// `validate`: the recipe checked offline against a skill-library file.
int validate(const std::string& file, const std::string& library_file);

struct RunOptions {
  std::string file;
  std::string recipe_text;  ///< when set, the recipe itself (file only names it in messages)
  std::string task_id;
  double timeout_s = 0;  // 0: no limit
  double match_timeout_s = 10;
  bool quiet = false;
};

/// `run`: submits the recipe and shows the live tree until the task ends.
int run_recipe(const CommonOptions& common, const RunOptions& opt);

/// `status` (task_id "") and `log TASK`: the journal's task list or a task's timeline.
int journal_query(const CommonOptions& common, const std::string& task_id, double timeout_s);

/// `tree TASK`: the last status of every node of a task.
int show_tree(const CommonOptions& common, const std::string& task_id, double timeout_s);

/// `skills`: the live executors and what they offer.
int show_skills(const CommonOptions& common, double timeout_s);

/// Sends CANCEL, PAUSE or RESUME for `task_id` and waits for the controller's acknowledgement on
/// rigger/task/status: the task's end for CANCEL, PAUSED for PAUSE, RUNNING for RESUME (or the task's
/// end, whichever comes first). Exit 0 when the wanted state was reached.
int task_command(const CommonOptions& common, const std::string& task_id, rigger_task_TaskCommandKind kind,
                 const std::string& reason, double timeout_s);

}  // namespace rigger::ctl::tasks
