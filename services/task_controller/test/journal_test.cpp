// The journal keeps accepted recipes and timelines across a reopen (the crash/restart case), and
// reports tasks that never finished.
#include "journal.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

class JournalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("rigger_journal_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "journal.sqlite").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(JournalTest, UnfinishedTaskSurvivesReopenAndIsReportedOnce) {
  {
    Journal j(path_);
    ASSERT_TRUE(j.add_task("t1", "{\"recipe\":1}", 10.0));
    ASSERT_TRUE(j.add_task("t2", "{}", 11.0));
    ASSERT_TRUE(j.finish_task("t2", "SUCCEEDED", "", "", 12.0));
    ASSERT_TRUE(j.add_record({10.5, "t1", "root/0", "NODE", "RUNNING", ""}));
  }  // closed without finishing t1, as a killed controller would leave it
  Journal j(path_);
  auto unfinished = j.unfinished_tasks();
  ASSERT_EQ(unfinished.size(), 1U);
  EXPECT_EQ(unfinished[0].task_id, "t1");
  EXPECT_EQ(unfinished[0].recipe_json, "{\"recipe\":1}");
  ASSERT_TRUE(j.finish_task("t1", "INTERRUPTED", "INTERRUPTED", "controller restarted", 20.0));
  EXPECT_TRUE(j.unfinished_tasks().empty());
  auto timeline = j.timeline("t1", 100);
  ASSERT_EQ(timeline.size(), 3U);
  EXPECT_EQ(timeline[0].kind, "RECIPE");
  EXPECT_EQ(timeline[1].node_id, "root/0");
  EXPECT_EQ(timeline[2].code, "INTERRUPTED");
}

TEST_F(JournalTest, AnInterruptedTaskIsFoundWithItsRecipeAndReopenedAsRunning) {
  Journal j(path_);
  ASSERT_TRUE(j.add_task("t1", "{\"recipe\":1}", 10.0));
  ASSERT_TRUE(j.finish_task("t1", "INTERRUPTED", "INTERRUPTED", "controller restarted", 20.0));
  const JournalTask t = j.task("t1");
  EXPECT_EQ(t.task_id, "t1");
  EXPECT_EQ(t.state, "INTERRUPTED");
  EXPECT_EQ(t.recipe_json, "{\"recipe\":1}");
  EXPECT_TRUE(j.task("nope").task_id.empty());
  ASSERT_TRUE(j.reopen_task("t1", "resumed; confirmed by alice", 30.0));
  EXPECT_EQ(j.task("t1").state, "RUNNING");
  ASSERT_EQ(j.unfinished_tasks().size(), 1U) << "a resumed task killed again is INTERRUPTED again";
  const auto timeline = j.timeline("t1", 100);
  ASSERT_EQ(timeline.size(), 3U);
  EXPECT_EQ(timeline[2].kind, "TASK");
  EXPECT_EQ(timeline[2].code, "RUNNING");
  EXPECT_EQ(timeline[2].message, "resumed; confirmed by alice");
}

TEST_F(JournalTest, ABatchOfRecordsIsStoredInOrderAndSurvivesReopen) {
  {
    Journal j(path_, JournalSync::kFull);
    ASSERT_TRUE(j.add_task("t", "{}", 1.0));
    ASSERT_TRUE(j.add_records({}));
    ASSERT_TRUE(j.add_records({{2.0, "t", "root/1", "EVENT", "FAILURE", "BENCH: fired"},
                               {2.0, "t", "root/1", "NODE", "FAILED", ""},
                               {2.1, "t", "root/0", "COMMAND", "SHUTDOWN", "sibling failed"}}));
    ASSERT_TRUE(j.add_record({3.0, "t", "root/0", "EVENT", "STOPPED", ""}));
  }
  Journal j(path_);
  const auto timeline = j.timeline("t", 100);
  ASSERT_EQ(timeline.size(), 5U);
  EXPECT_EQ(timeline[1].code, "FAILURE");
  EXPECT_EQ(timeline[2].code, "FAILED");
  EXPECT_EQ(timeline[3].code, "SHUTDOWN");
  EXPECT_EQ(timeline[3].message, "sibling failed");
  EXPECT_EQ(timeline[4].code, "STOPPED");
}

TEST_F(JournalTest, DuplicateTaskIdIsRefused) {
  Journal j(path_);
  ASSERT_TRUE(j.add_task("t", "{}", 1.0));
  EXPECT_TRUE(j.has_task("t"));
  EXPECT_FALSE(j.has_task("other"));
  EXPECT_FALSE(j.add_task("t", "{}", 2.0));
}

TEST_F(JournalTest, TimelineIsBoundedAndOrdered) {
  Journal j(path_);
  ASSERT_TRUE(j.add_task("t", "{}", 1.0));
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(j.add_record({2.0 + i, "t", "n" + std::to_string(i), "EVENT", "", ""}));
  auto timeline = j.timeline("t", 10);
  ASSERT_EQ(timeline.size(), 10U);
  EXPECT_EQ(timeline[0].kind, "RECIPE");
  EXPECT_EQ(timeline[1].node_id, "n0");
  EXPECT_TRUE(j.timeline("missing", 10).empty());
}

TEST_F(JournalTest, StrangeTextIsStoredVerbatim) {
  Journal j(path_);
  const std::string text = std::string("quote ' \" nul-free \xff\xfe bytes; DROP TABLE tasks;");
  ASSERT_TRUE(j.add_task("t'; --", text, 1.0));
  auto tasks = j.tasks(10);
  ASSERT_EQ(tasks.size(), 1U);
  EXPECT_EQ(tasks[0].recipe_json, text);
  EXPECT_EQ(tasks[0].task_id, "t'; --");
}

TEST_F(JournalTest, MissingFolderIsCreated) {
  Journal journal((dir_ / "missing-dir" / "j.sqlite").string());
  EXPECT_TRUE(std::filesystem::exists(dir_ / "missing-dir" / "j.sqlite"));
}

TEST_F(JournalTest, UnopenablePathThrows) {
  // A regular file where the folder should be: the folder cannot be created, the database not opened.
  std::ofstream(dir_ / "a-file") << "x";
  EXPECT_THROW(Journal((dir_ / "a-file" / "j.sqlite").string()), JournalError);
}

}  // namespace
}  // namespace rigger::task_controller
