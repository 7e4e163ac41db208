// The journal server's answers: bounded, a timeline per task or the task list, an unknown task said so.

#include "journal_server.hpp"

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

TEST(JournalQueryLimit, DefaultsAndCaps) {
  EXPECT_EQ(journal_query_limit(0), kDefaultJournalEntries);
  EXPECT_EQ(journal_query_limit(1), 1U);
  EXPECT_EQ(journal_query_limit(10000), 10000U);
  EXPECT_EQ(journal_query_limit(10001), kMaxJournalEntries);
  EXPECT_EQ(journal_query_limit(4294967295U), kMaxJournalEntries);
}

class JournalServerAnswer : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(journal_.add_task("older", "{}", 100.0));
    ASSERT_TRUE(journal_.add_task("newer", "{}", 200.0));
    ASSERT_TRUE(journal_.finish_task("older", "SUCCEEDED", "", "", 150.0));
    std::vector<JournalRecord> rows;
    for (int i = 0; i < 30; ++i) rows.push_back({101.0 + i, "older", "root", "NODE", "RUNNING", std::to_string(i)});
    ASSERT_TRUE(journal_.add_records(rows));
  }
  Journal journal_{":memory:"};
};

TEST_F(JournalServerAnswer, ATaskGetsItsTimelineBounded) {
  const auto all = answer_query(journal_, "older", 0);
  ASSERT_TRUE(all.ok) << all.message;
  EXPECT_GE(all.records.size(), 30U);
  for (const auto& r : all.records) EXPECT_EQ(r.task_id, "older");
  const auto five = answer_query(journal_, "older", 5);
  ASSERT_TRUE(five.ok);
  EXPECT_EQ(five.records.size(), 5U);
}

TEST_F(JournalServerAnswer, NoTaskGetsTheTasksNewestFirst) {
  const auto a = answer_query(journal_, "", 0);
  ASSERT_TRUE(a.ok);
  ASSERT_EQ(a.records.size(), 2U);
  EXPECT_EQ(a.records[0].task_id, "newer");
  EXPECT_EQ(a.records[0].kind, "TASK");
  EXPECT_EQ(a.records[0].code, "RUNNING");
  EXPECT_EQ(a.records[1].task_id, "older");
  EXPECT_EQ(a.records[1].code, "SUCCEEDED");
  EXPECT_EQ(answer_query(journal_, "", 1).records.size(), 1U);
}

TEST_F(JournalServerAnswer, AnUnknownTaskIsNotOk) {
  const auto a = answer_query(journal_, "nope", 0);
  EXPECT_FALSE(a.ok);
  EXPECT_EQ(a.message, "no such task in the journal");
  EXPECT_TRUE(a.records.empty());
}

}  // namespace
}  // namespace rigger::task_controller
