#pragma once
/// @file
/// The task controller's journal (nothing is lost): every accepted recipe and every
/// event/transition, with wall-clock timestamps, in one SQLite file.
///
/// Durability: WAL mode; the sync level is the caller's choice (`JournalSync`).
///  - kNormal (the controller's default): no fsync per commit. A committed row survives a crash or
///    restart of the controller (it is in the WAL file); an OS crash or power cut may lose the last
///    commits (never corrupt the file).
///  - kFull: an fsync per commit; every row also survives a power cut.
/// The controller writes a recipe (add_task) before acting on it, and an event's rows in one
/// add_records() transaction after it sent the commands the event caused, on its side-effect thread
/// (side_effect_writer.hpp: so neither an fsync nor a WAL checkpoint is ever between a monitor's FAILURE
/// and the sibling's SHUTDOWN).
///
/// Thread safety: every member locks the journal, so the controller's loop and its side-effect
/// thread may share it. Errors at open throw
/// JournalError; in steady state write errors are returned (false) so the caller can log them.

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace rigger::task_controller {

class JournalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One timeline line.
struct JournalRecord {
  double stamp_s = 0;   ///< wall clock, seconds since the Unix epoch
  std::string task_id;
  std::string node_id;  ///< "" for task-level lines
  /// "RECIPE", "TASK", "NODE", "EVENT", "COMMAND", "OPERATOR", "RESUME", "ESCALATION", "REJECTED_EVENT"
  std::string kind;
  std::string code;
  std::string message;
};

/// A task as the journal knows it.
struct JournalTask {
  std::string task_id;
  std::string state;  ///< "RUNNING", "SUCCEEDED", "FAILED", "CANCELED", "INTERRUPTED"
  double submitted_s = 0;
  std::string recipe_json;
};

/// How hard a commit is pushed to disk (see the file comment).
enum class JournalSync { kNormal, kFull };

class Journal {
 public:
  /// Opens (creating) the journal at `path` (":memory:" for tests). @throws JournalError.
  explicit Journal(const std::string& path, JournalSync sync = JournalSync::kNormal);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  /// Records an accepted recipe; the task is RUNNING (unfinished) until finish_task().
  bool add_task(const std::string& task_id, const std::string& recipe_json, double stamp_s);
  /// Marks a task finished with `state` ("SUCCEEDED", "FAILED", "CANCELED", "INTERRUPTED").
  bool finish_task(const std::string& task_id, const std::string& state, const std::string& code,
                   const std::string& message, double stamp_s);
  /// An INTERRUPTED task resumed (riggerctl resume, confirmed by the operator): RUNNING again, with a
  /// `TASK RUNNING` line saying why.
  bool reopen_task(const std::string& task_id, const std::string& message, double stamp_s);
  /// Appends one timeline line.
  bool add_record(const JournalRecord& record);
  /// Appends `records` in one transaction: all or none (one commit, so one fsync with kFull).
  /// `why`, when given, receives the error of a failed call (read under the same lock).
  bool add_records(const std::vector<JournalRecord>& records, std::string* why = nullptr);

  /// Tasks whose state is still RUNNING (the controller died while they ran).
  std::vector<JournalTask> unfinished_tasks() const;
  /// The task `task_id` with its recipe, or an empty task_id when the journal does not know it.
  JournalTask task(const std::string& task_id) const;
  /// Whether the journal knows `task_id` (finished or not).
  bool has_task(const std::string& task_id) const;
  /// The timeline of one task in order, at most `max_entries` (the newest are dropped).
  std::vector<JournalRecord> timeline(const std::string& task_id, std::size_t max_entries) const;
  /// Every task, newest first, at most `max_tasks`.
  std::vector<JournalTask> tasks(std::size_t max_tasks) const;

  /// Last SQLite error text.
  std::string last_error() const;

 private:
  bool exec(const char* sql);
  bool insert_record(const JournalRecord& record);  ///< the lock held
  std::string error_text() const;                   ///< the lock held
  mutable std::mutex mutex_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_record_ = nullptr;
  std::string rollback_error_;  ///< why the last add_records() rolled back, until the next exec()  ///< prepared once: add_record() runs for every event
};

/// Wall-clock now in seconds since the epoch.
double wall_now_s();

}  // namespace rigger::task_controller
