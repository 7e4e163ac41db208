#pragma once
/// @file
/// The plots of each task run, kept on disk with the run, so that a finished task can be replayed after
/// a console restart or a day later (the console's memory holds only the last 30 minutes). One folder
/// per task under the archive's folder:
///
///   <folder>/<task_id>/plots.jsonl   the console's plot rows while the task was active, one JSON object
///                                    per line, as /api/plots serves them ({"t": seconds, ...})
///   <folder>/<task_id>/cell.jsonl    where things were in the cell (cell_feed.hpp): the whole picture
///                                    when the run began, then each change, one JSON object per line
///   <folder>/<task_id>/run.json      {"task_id", "state", "first", "last", "rows", "cell_rows", "truncated"}
///
/// A run begins when the task is first seen ACCEPTED, RUNNING or PAUSED, and ends at its final state
/// (SUCCEEDED, FAILED, CANCELED, REJECTED); a task id run again starts a new run (the old one is
/// replaced). A console that restarts during a run goes on appending to it. At most `max_runs` runs are
/// kept (the oldest finished ones are removed), and `max_rows` plot rows and as many cell rows per run
/// (then the run is marked truncated). Rows are written as they come, so a crash loses at most the row being written.
///
/// Thread safety: on_task(), on_row() and on_cell() run on the console's loop; runs() and rows() on HTTP threads.
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace rigger::console {

/// A plot row's time (s since the epoch): the console writes "t" first ({"t":<seconds>,...}), so it is
/// read without parsing the row; another row is parsed. 0 when the row has none.
double plot_row_time(const std::string& row);

class RunArchive {
 public:
  struct Limits {
    std::size_t max_runs = 200;
    std::size_t max_rows = 200000;  ///< 2 h 45 min at 20 rows per second
  };

  /// Opens (creating it) the archive folder and reads what it holds. @throws std::runtime_error naming the
  /// folder when it cannot be created or read.
  RunArchive(std::filesystem::path folder, Limits limits);
  ~RunArchive();
  RunArchive(const RunArchive&) = delete;
  RunArchive& operator=(const RunArchive&) = delete;

  /// A task's status, with its time (s since the epoch). Task ids outside the recipe format
  /// ([A-Za-z0-9][A-Za-z0-9_.-]{0,127}) are not recorded.
  void on_task(const std::string& task_id, const std::string& state, double stamp_s);
  /// A plot row: appended to the run of every active task.
  void on_row(const std::string& row_json);
  /// A change of where things are in the cell (cell_feed.hpp): appended to the run of every active task.
  void on_cell(const nlohmann::json& change);

  /// The runs kept, newest first: each run.json's content.
  nlohmann::json runs() const;
  /// A run's rows as one JSON array text, or nullopt when no run of `task_id` is kept.
  std::optional<std::string> rows(const std::string& task_id) const;
  /// A run's cell rows (the picture when it began, then the changes) as one JSON array text, or nullopt
  /// when no run of `task_id` is kept.
  std::optional<std::string> cell_rows(const std::string& task_id) const;

 private:
  struct Run {
    nlohmann::json meta;  ///< run.json
    std::ofstream rows;   ///< open while the task is active
    std::ofstream cell;   ///< open while the task is active
  };
  /// Appends `line` to `out` unless the run holds `max_rows` of `count_key` already.
  void append(Run& run, std::ofstream& out, const char* count_key, const std::string& line);
  std::optional<std::string> read_rows(const std::string& task_id, const char* file, const char* count_key) const;
  void begin(const std::string& task_id, const std::string& state, double stamp_s);
  void finish(Run& run, const std::string& state, double stamp_s);
  void write_meta(const Run& run) const;
  void prune();

  const std::filesystem::path folder_;
  const Limits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, Run> runs_;  ///< by task id
  nlohmann::json cell_ = nlohmann::json::object();  ///< the latest picture, the first row of a new run
};

}  // namespace rigger::console
