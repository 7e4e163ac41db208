#include "journal.hpp"

#include <chrono>
#include <filesystem>
#include <memory>

#include <sqlite3.h>

namespace rigger::task_controller {
namespace {

struct StmtDeleter {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Stmt = std::unique_ptr<sqlite3_stmt, StmtDeleter>;

Stmt prepare(sqlite3* db, const char* sql) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK) return Stmt(nullptr);
  return Stmt(s);
}

void bind_text(sqlite3_stmt* s, int i, const std::string& v) {
  sqlite3_bind_text(s, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
}

std::string column_text(sqlite3_stmt* s, int i) {
  const auto* p = sqlite3_column_text(s, i);
  return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(s, i)))
           : std::string();
}

}  // namespace

double wall_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Journal::Journal(const std::string& path, JournalSync sync) {
  // The journal's folder is created on first use (e.g. /var/tmp/rigger on a fresh machine); a failure
  // shows in sqlite3_open's error below.
  if (const auto folder = std::filesystem::path(path).parent_path(); !folder.empty()) {
    std::error_code ignored;
    std::filesystem::create_directories(folder, ignored);
  }
  if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) {
    std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw JournalError("cannot open journal " + path + ": " + why);
  }
  sqlite3_busy_timeout(db_, 2000);
  // See the header for the two sync levels.
  const bool ok = exec("PRAGMA journal_mode=WAL;") &&
                  exec(sync == JournalSync::kFull ? "PRAGMA synchronous=FULL;" : "PRAGMA synchronous=NORMAL;") &&
                  exec("CREATE TABLE IF NOT EXISTS tasks (task_id TEXT PRIMARY KEY, state TEXT NOT NULL, "
                       "submitted REAL NOT NULL, finished REAL, code TEXT, message TEXT, recipe TEXT NOT NULL);") &&
                  exec("CREATE TABLE IF NOT EXISTS records (id INTEGER PRIMARY KEY AUTOINCREMENT, stamp REAL NOT NULL, "
                       "task_id TEXT NOT NULL, node_id TEXT NOT NULL, kind TEXT NOT NULL, code TEXT NOT NULL, "
                       "message TEXT NOT NULL);") &&
                  exec("CREATE INDEX IF NOT EXISTS records_task ON records(task_id, id);") &&
                  sqlite3_prepare_v2(db_,
                                     "INSERT INTO records(stamp, task_id, node_id, kind, code, message) "
                                     "VALUES(?, ?, ?, ?, ?, ?);",
                                     -1, &insert_record_, nullptr) == SQLITE_OK;
  if (!ok) {
    std::string why = last_error();
    sqlite3_finalize(insert_record_);
    sqlite3_close(db_);
    db_ = nullptr;
    throw JournalError("cannot initialise journal " + path + ": " + why);
  }
}

Journal::~Journal() {
  sqlite3_finalize(insert_record_);
  sqlite3_close(db_);
}

std::string Journal::last_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_text();
}

std::string Journal::error_text() const {
  if (!rollback_error_.empty()) return rollback_error_;
  return db_ ? sqlite3_errmsg(db_) : "journal not open";
}

bool Journal::exec(const char* sql) {
  rollback_error_.clear();
  return sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) == SQLITE_OK;
}

bool Journal::add_task(const std::string& task_id, const std::string& recipe_json, double stamp_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = prepare(db_, "INSERT INTO tasks(task_id, state, submitted, recipe) VALUES(?, 'RUNNING', ?, ?);");
  if (!s) return false;
  bind_text(s.get(), 1, task_id);
  sqlite3_bind_double(s.get(), 2, stamp_s);
  bind_text(s.get(), 3, recipe_json);
  if (sqlite3_step(s.get()) != SQLITE_DONE) return false;
  return insert_record({stamp_s, task_id, "", "RECIPE", "ACCEPTED", "recipe accepted"});
}

bool Journal::finish_task(const std::string& task_id, const std::string& state, const std::string& code,
                          const std::string& message, double stamp_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = prepare(db_, "UPDATE tasks SET state=?, finished=?, code=?, message=? WHERE task_id=?;");
  if (!s) return false;
  bind_text(s.get(), 1, state);
  sqlite3_bind_double(s.get(), 2, stamp_s);
  bind_text(s.get(), 3, code);
  bind_text(s.get(), 4, message);
  bind_text(s.get(), 5, task_id);
  if (sqlite3_step(s.get()) != SQLITE_DONE) return false;
  return insert_record({stamp_s, task_id, "", "TASK", state, code.empty() ? message : code + ": " + message});
}

bool Journal::reopen_task(const std::string& task_id, const std::string& message, double stamp_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = prepare(db_, "UPDATE tasks SET state='RUNNING', finished=NULL, code=NULL, message=NULL WHERE task_id=?;");
  if (!s) return false;
  bind_text(s.get(), 1, task_id);
  if (sqlite3_step(s.get()) != SQLITE_DONE) return false;
  return insert_record({stamp_s, task_id, "", "TASK", "RUNNING", message});
}

bool Journal::add_record(const JournalRecord& record) {
  std::lock_guard<std::mutex> lock(mutex_);
  return insert_record(record);
}

bool Journal::insert_record(const JournalRecord& r) {
  sqlite3_stmt* s = insert_record_;
  sqlite3_reset(s);
  sqlite3_bind_double(s, 1, r.stamp_s);
  bind_text(s, 2, r.task_id);
  bind_text(s, 3, r.node_id);
  bind_text(s, 4, r.kind);
  bind_text(s, 5, r.code);
  bind_text(s, 6, r.message);
  return sqlite3_step(s) == SQLITE_DONE;
}

bool Journal::add_records(const std::vector<JournalRecord>& records, std::string* why) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto failed = [&] {
    if (why) *why = error_text();
    return false;
  };
  if (!exec("BEGIN;")) return failed();
  for (const auto& r : records) {
    if (!insert_record(r)) {
      std::string error = sqlite3_errmsg(db_);  // ROLLBACK overwrites SQLite's message
      exec("ROLLBACK;");
      rollback_error_ = std::move(error);
      return failed();
    }
  }
  return exec("COMMIT;") || failed();
}

std::vector<JournalTask> Journal::unfinished_tasks() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JournalTask> out;
  auto s = prepare(db_, "SELECT task_id, state, submitted, recipe FROM tasks WHERE state='RUNNING' ORDER BY submitted;");
  if (!s) return out;
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({column_text(s.get(), 0), column_text(s.get(), 1), sqlite3_column_double(s.get(), 2),
                   column_text(s.get(), 3)});
  return out;
}

JournalTask Journal::task(const std::string& task_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = prepare(db_, "SELECT task_id, state, submitted, recipe FROM tasks WHERE task_id=?;");
  if (!s) return {};
  bind_text(s.get(), 1, task_id);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return {};
  return {column_text(s.get(), 0), column_text(s.get(), 1), sqlite3_column_double(s.get(), 2), column_text(s.get(), 3)};
}

bool Journal::has_task(const std::string& task_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto s = prepare(db_, "SELECT 1 FROM tasks WHERE task_id=?;");
  if (!s) return false;
  bind_text(s.get(), 1, task_id);
  return sqlite3_step(s.get()) == SQLITE_ROW;
}

std::vector<JournalRecord> Journal::timeline(const std::string& task_id, std::size_t max_entries) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JournalRecord> out;
  auto s = prepare(db_, "SELECT stamp, task_id, node_id, kind, code, message FROM records WHERE task_id=? "
                        "ORDER BY id LIMIT ?;");
  if (!s) return out;
  bind_text(s.get(), 1, task_id);
  sqlite3_bind_int64(s.get(), 2, static_cast<sqlite3_int64>(max_entries));
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({sqlite3_column_double(s.get(), 0), column_text(s.get(), 1), column_text(s.get(), 2),
                   column_text(s.get(), 3), column_text(s.get(), 4), column_text(s.get(), 5)});
  return out;
}

std::vector<JournalTask> Journal::tasks(std::size_t max_tasks) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JournalTask> out;
  auto s = prepare(db_, "SELECT task_id, state, submitted, recipe FROM tasks ORDER BY submitted DESC LIMIT ?;");
  if (!s) return out;
  sqlite3_bind_int64(s.get(), 1, static_cast<sqlite3_int64>(max_tasks));
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({column_text(s.get(), 0), column_text(s.get(), 1), sqlite3_column_double(s.get(), 2),
                   column_text(s.get(), 3)});
  return out;
}

}  // namespace rigger::task_controller
