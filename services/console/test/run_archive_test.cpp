// The run archive keeps each task run's plot rows on disk: across a restart, through a crash during a
// run, bounded in runs and rows, and never mixing two runs of one task id.
#include "run_archive.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace rigger::console {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class RunArchiveTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("run-archive-" + std::to_string(::getpid()) + "-" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // As the console writes them: "t" first.
  static std::string row(double t, double f) { return nlohmann::ordered_json{{"t", t}, {"f", f}}.dump(); }
  fs::path dir_;
};

TEST_F(RunArchiveTest, RunOfATaskSurvivesARestart) {
  {
    RunArchive archive(dir_, {});
    archive.on_row(row(99, 0));  // no task active: not kept
    archive.on_task("insert", "ACCEPTED", 100);
    archive.on_task("insert", "RUNNING", 100.1);
    archive.on_row(row(100.5, 12.5));
    archive.on_row(row(101.0, 40.25));
    archive.on_task("insert", "SUCCEEDED", 101.2);
    archive.on_row(row(102, 0));  // after the end: not kept
  }
  RunArchive reopened(dir_, {});
  const json runs = reopened.runs();
  ASSERT_EQ(runs.size(), 1u) << runs.dump();
  EXPECT_EQ(runs[0]["task_id"], "insert");
  EXPECT_EQ(runs[0]["state"], "SUCCEEDED");
  EXPECT_EQ(runs[0]["rows"], 2);
  EXPECT_DOUBLE_EQ(runs[0]["first"].get<double>(), 100.5);
  EXPECT_DOUBLE_EQ(runs[0]["last"].get<double>(), 101.0);
  const auto rows = json::parse(*reopened.rows("insert"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[1]["f"].get<double>(), 40.25);
  EXPECT_FALSE(reopened.rows("other"));
  EXPECT_FALSE(reopened.rows("../insert"));
}

TEST_F(RunArchiveTest, ConsoleStoppedDuringARunGoesOnAppending) {
  {
    RunArchive archive(dir_, {});
    archive.on_task("t1", "RUNNING", 10);
    archive.on_row(row(10.5, 1));
  }  // the console stops while t1 runs
  {
    // A crash can leave half a row: it is not served.
    std::ofstream(dir_ / "t1" / "plots.jsonl", std::ios::app) << "{\"t\":10.7,\"f\"";
  }
  RunArchive archive(dir_, {});
  archive.on_task("t1", "RUNNING", 10);  // the last status, as DDS gives it again
  std::ofstream(dir_ / "t1" / "plots.jsonl", std::ios::app) << "\n";
  archive.on_row(row(11, 2));
  archive.on_task("t1", "FAILED", 11.5);
  const auto rows = json::parse(*archive.rows("t1"));
  ASSERT_EQ(rows.size(), 2u) << rows.dump();
  EXPECT_DOUBLE_EQ(rows[0]["t"].get<double>(), 10.5);
  EXPECT_DOUBLE_EQ(rows[1]["t"].get<double>(), 11);
  EXPECT_EQ(archive.runs()[0]["state"], "FAILED");
}

TEST_F(RunArchiveTest, ATaskRunAgainReplacesItsRunAndALateSampleDoesNot) {
  RunArchive archive(dir_, {});
  archive.on_task("t", "RUNNING", 1);
  archive.on_row(row(1.5, 1));
  archive.on_task("t", "SUCCEEDED", 2);
  archive.on_task("t", "RUNNING", 1.8);  // older than the end: a late sample of the same run
  EXPECT_EQ(archive.runs()[0]["state"], "SUCCEEDED");
  archive.on_task("t", "ACCEPTED", 3);  // the same id published again
  archive.on_row(row(3.5, 7));
  const auto rows = json::parse(*archive.rows("t"));
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_DOUBLE_EQ(rows[0]["f"].get<double>(), 7);
}

TEST_F(RunArchiveTest, KeepsAtMostMaxRunsAndMaxRows) {
  RunArchive archive(dir_, {2, 3});
  for (int i = 0; i < 3; ++i) {
    const std::string id = "task" + std::to_string(i);
    archive.on_task(id, "RUNNING", 10.0 * i);
    for (int k = 0; k < 5; ++k) archive.on_row(row(10.0 * i + k, k));
    archive.on_task(id, "SUCCEEDED", 10.0 * i + 6);
  }
  const json runs = archive.runs();
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0]["task_id"], "task2");  // newest first
  EXPECT_EQ(runs[1]["task_id"], "task1");
  EXPECT_FALSE(fs::exists(dir_ / "task0"));
  EXPECT_EQ(runs[0]["rows"], 3);
  EXPECT_TRUE(runs[0]["truncated"].get<bool>());
  EXPECT_EQ(json::parse(*archive.rows("task2")).size(), 3u);
}

TEST_F(RunArchiveTest, CellRowsBeginWithThePictureAndSurviveARestartMidRun) {
  {
    RunArchive archive(dir_, {10, 4});
    archive.on_cell(json::parse(R"({"t": 5, "objects": {"a": {"position_m": [1, 0, 0]}}, "hook": [0, 0, 4]})"));
    archive.on_cell(json::parse(R"({"t": 6, "objects": {"b": {"position_m": [2, 0, 0]}}})"));
    archive.on_task("lift", "RUNNING", 7);
    archive.on_cell(json::parse(R"({"t": 8, "hook": [0, 0, 3]})"));
  }  // the console stops during the run
  RunArchive archive(dir_, {10, 4});
  archive.on_task("lift", "RUNNING", 7);
  for (double t : {9.0, 10.0, 11.0}) archive.on_cell({{"t", t}, {"hook", {0, 0, 12 - t}}});
  archive.on_task("lift", "SUCCEEDED", 12);
  archive.on_cell(json::parse(R"({"t": 13, "hook": [0, 0, 0]})"));  // after the end: not kept
  const json rows = json::parse(*archive.cell_rows("lift"));
  ASSERT_EQ(rows.size(), 4u) << rows.dump();  // bounded by max_rows
  // The first row: everything as it was when the run began, at the run's start.
  EXPECT_EQ(rows[0]["t"], 7);
  EXPECT_EQ(rows[0]["objects"].size(), 2u) << rows[0].dump();
  EXPECT_EQ(rows[0]["hook"][2], 4);
  EXPECT_EQ(rows[1]["hook"][2], 3);
  EXPECT_EQ(rows[3]["t"], 10);
  EXPECT_EQ(archive.runs()[0]["cell_rows"], 4);
  EXPECT_TRUE(archive.runs()[0]["truncated"].get<bool>());
  EXPECT_FALSE(archive.cell_rows("other"));
}

TEST_F(RunArchiveTest, IgnoresWhatItDidNotWrite) {
  fs::create_directories(dir_ / "notes");
  std::ofstream(dir_ / "notes" / "run.json") << "{\"task_id\": \"elsewhere\"}";
  fs::create_directories(dir_ / "junk");
  std::ofstream(dir_ / "junk" / "run.json") << "not json";
  RunArchive archive(dir_, {});
  EXPECT_TRUE(archive.runs().empty());
  archive.on_task("bad id with spaces", "RUNNING", 1);
  EXPECT_TRUE(archive.runs().empty());
}

TEST_F(RunArchiveTest, UnusableFolderIsNamed) {
  std::ofstream(dir_.string()) << "a file, not a folder";
  try {
    RunArchive archive(dir_ / "runs", {});
    FAIL() << "opened an archive below a file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir_.string()), std::string::npos) << e.what();
  }
  fs::remove(dir_);
}

}  // namespace
}  // namespace rigger::console
