#pragma once
// A benchmark's figures as it saves them (test/bench/results/<bench>.json) and as
// docs/performance.md shows them: each figure next to the reference measured in the same run.
//
//   rigger::performance::Report report("bench_world_query", "World-model pose query round trip");
//   report.add({"query p99", r99, "us", "ddsperf ping/pong 128 B p99", ref.p99_us});
//   report.save();  // writes $RIGGER_BENCH_RESULTS/bench_world_query.json when that is set
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::performance {

/// One figure of a bench.
struct Figure {
  std::string name;            ///< what was measured, e.g. "SUCCESS -> next START p99"
  double value = 0;
  std::string unit;            ///< e.g. "us", "ms", "x real time", "MiB"
  std::string reference;       ///< what the same run measured to compare with; empty: none
  double reference_value = 0;  ///< in `unit`
};

/// The machine a bench ran on, as /proc and uname describe it.
struct Machine {
  std::string cpu;
  int cores = 0;
  std::string kernel;
};

/// The figures of one run of one bench.
struct BenchResult {
  std::string bench;         ///< the program's name
  std::string title;         ///< one line: what the bench measures
  std::string measured_utc;  ///< ISO 8601, e.g. 2026-11-28T10:55:00Z
  Machine machine;
  std::vector<Figure> figures;
};

/// This machine.
Machine this_machine();

nlohmann::json to_json(const BenchResult& result);

/// A result from its JSON: ours (to_json), or Google Benchmark's `--benchmark_out` format (each
/// benchmark's real time and its counters become figures). @throws std::runtime_error naming `where`
/// and the field that is missing or of the wrong type.
BenchResult result_from_json(const nlohmann::json& json, const std::string& where);

/// Every *.json in `folder`, sorted by bench name. @throws std::runtime_error naming the file.
std::vector<BenchResult> read_results(const std::filesystem::path& folder);

/// docs/performance.md for these results.
std::string performance_markdown(const std::vector<BenchResult>& results);

/// Collects a bench's figures; save() writes them to $RIGGER_BENCH_RESULTS/<bench>.json.
class Report {
 public:
  Report(std::string bench, std::string title);
  void add(Figure figure) { result_.figures.push_back(std::move(figure)); }
  /// Writes the file (atomically) when RIGGER_BENCH_RESULTS names a folder, and returns its path;
  /// returns an empty path when it is not set. @throws std::runtime_error when the file cannot be written.
  std::filesystem::path save();

 private:
  BenchResult result_;
};

/// `report.save()` for a bench's main: 0 when saved (or when RIGGER_BENCH_RESULTS is not set), 1 with
/// why on stderr when the file cannot be written.
int save_for_main(Report& report);

}  // namespace rigger::performance
