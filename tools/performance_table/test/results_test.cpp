// The checked-in performance page is what the benches' saved results say, and results read back as
// they were written. When CheckedInPageIsCurrent fails, run test/bench/run (or the generator alone:
// build/bin/rigger-performance-table test/bench/results > docs/performance.md) and commit both.
#include "rigger/performance/results.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

namespace rigger::performance {
namespace {

const std::string kSource = RIGGER_SOURCE_DIR;

TEST(PerformanceTable, CheckedInPageIsCurrent) {
  std::ifstream in(kSource + "/docs/performance.md");
  std::ostringstream page;
  page << in.rdbuf();
  EXPECT_EQ(page.str(), performance_markdown(read_results(kSource + "/test/bench/results")))
      << "docs/performance.md is out of date: run build/bin/rigger-performance-table test/bench/results";
}

TEST(PerformanceTable, ResultRoundTripsAndShowsItsRatio) {
  BenchResult r{"bench_x", "what x measures", "2026-01-01T00:00:00Z", {"cpu", 2, "Linux 6"}, {}};
  r.figures.push_back({"reaction p99", 150, "us", "relay p99", 120});
  r.figures.push_back({"memory", 12.5, "MiB", "", 0});
  const BenchResult back = result_from_json(to_json(r), "test");
  ASSERT_EQ(back.figures.size(), 2u);
  EXPECT_EQ(back.figures[0].reference, "relay p99");
  EXPECT_DOUBLE_EQ(back.figures[0].reference_value, 120);
  EXPECT_EQ(to_json(back), to_json(r));
  const std::string md = performance_markdown({back});
  EXPECT_NE(md.find("| reaction p99 | 150 | us | relay p99 | 120 | 1.25 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| memory | 12.5 | MiB |  |  |  |"), std::string::npos) << md;
}

TEST(PerformanceTable, MalformedResultNamesFileAndField) {
  auto json = to_json({"bench_x", "t", "2026-01-01T00:00:00Z", {"cpu", 2, "k"}, {{"f", 1, "us", "", 0}}});
  json["figures"][0]["value"] = "fast";
  try {
    result_from_json(json, "results/bench_x.json");
    FAIL() << "accepted a figure whose value is a string";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "results/bench_x.json/figures/0: \"value\" must be a number");
  }
}

TEST(PerformanceTable, GoogleBenchmarkOutputBecomesFigures) {
  const auto json = nlohmann::json::parse(R"({
    "context": {"date": "2026-01-01T00:00:00+00:00", "host_name": "h", "executable": "/b/bench/physics_bench",
                "num_cpus": 2},
    "benchmarks": [
      {"name": "BM_Step", "run_type": "iteration", "iterations": 10, "real_time": 41.5, "cpu_time": 41.0,
       "time_unit": "us", "steps_per_s": 24000.0},
      {"name": "BM_Step_stddev", "run_type": "aggregate", "aggregate_name": "stddev", "real_time": 1.0,
       "time_unit": "us"}]})");
  const BenchResult r = result_from_json(json, "g.json");
  EXPECT_EQ(r.bench, "physics_bench");
  ASSERT_EQ(r.figures.size(), 2u);
  EXPECT_EQ(r.figures[0].name, "BM_Step");
  EXPECT_DOUBLE_EQ(r.figures[0].value, 41.5);
  EXPECT_EQ(r.figures[1].name, "BM_Step steps_per_s");
}

}  // namespace
}  // namespace rigger::performance
