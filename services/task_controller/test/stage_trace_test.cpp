// The stage trace: each stage once per event, in order; the first command counts; a flush covers every
// event before it; the capacity bounds it; the file reads back as written, the loop marks beside it.

#include "stage_trace.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>

namespace rigger::task_controller {
namespace {

TEST(StageTrace, RecordsEachStageOnceInOrder) {
  StageTrace t;
  t.woke();
  t.begin("monitors", "FAILURE", 42);
  t.command_writing();
  t.command_written();
  const auto first = t.records().back().command_ns;
  t.command_written();  // a second command of the same event does not move the first
  t.engine_done();
  t.begin("skills", "PROGRESS", 43);  // same wake, no command
  t.engine_done();
  t.flushed();
  t.command_written();  // outside any event: not attributed to the last one
  ASSERT_EQ(t.records().size(), 2U);
  const auto& a = t.records()[0];
  EXPECT_EQ(a.executor_id, "monitors");
  EXPECT_EQ(a.kind, "FAILURE");
  EXPECT_EQ(a.stamp_wall_ns, 42);
  EXPECT_GT(a.woke_ns, 0);
  EXPECT_EQ(a.command_ns, first);
  EXPECT_LE(a.woke_ns, a.writing_ns);
  EXPECT_LE(a.writing_ns, a.command_ns);
  EXPECT_LE(a.command_ns, a.engine_ns);
  EXPECT_LE(a.engine_ns, a.flushed_ns);
  const auto& b = t.records()[1];
  EXPECT_EQ(b.woke_ns, a.woke_ns);
  EXPECT_EQ(b.command_ns, 0);
  EXPECT_EQ(b.flushed_ns, a.flushed_ns);
}

TEST(StageTrace, AFlushCoversOnlyTheEventsBeforeIt) {
  StageTrace t;
  t.woke();
  t.begin("x", "SUCCESS", 1);
  t.engine_done();
  t.flushed();
  const auto flushed = t.records()[0].flushed_ns;
  t.woke();
  t.begin("x", "SUCCESS", 2);
  t.engine_done();
  EXPECT_EQ(t.records()[1].flushed_ns, 0);
  t.flushed();
  EXPECT_EQ(t.records()[0].flushed_ns, flushed);
  EXPECT_GE(t.records()[1].flushed_ns, flushed);
}

TEST(StageTrace, StopsRecordingAtCapacity) {
  StageTrace t(1);
  t.woke();
  t.begin("x", "SUCCESS", 1);
  t.engine_done();
  t.begin("x", "SUCCESS", 2);
  t.command_written();
  t.engine_done();
  ASSERT_EQ(t.records().size(), 1U);
  EXPECT_EQ(t.records()[0].command_ns, 0);
}

TEST(StageTrace, ReadsBackWhatItWrote) {
  StageTrace t;
  t.woke();
  t.begin("monitors", "FAILURE", 1700000000123456789LL);
  t.command_writing();
  t.command_written();
  t.engine_done();
  t.flushed();
  const std::string path = ::testing::TempDir() + "stage_trace_test_" + std::to_string(::getpid()) + ".tsv";
  ASSERT_TRUE(t.write(path));
  const auto back = StageTrace::read(path);
  std::remove(path.c_str());
  ASSERT_EQ(back.size(), 1U);
  const auto& a = t.records()[0];
  const auto& b = back[0];
  EXPECT_EQ(b.executor_id, a.executor_id);
  EXPECT_EQ(b.kind, a.kind);
  EXPECT_EQ(b.stamp_wall_ns, a.stamp_wall_ns);
  EXPECT_EQ(b.woke_wall_ns, a.woke_wall_ns);
  EXPECT_EQ(b.woke_ns, a.woke_ns);
  EXPECT_EQ(b.writing_ns, a.writing_ns);
  EXPECT_EQ(b.command_ns, a.command_ns);
  EXPECT_EQ(b.engine_ns, a.engine_ns);
  EXPECT_EQ(b.flushed_ns, a.flushed_ns);
  EXPECT_TRUE(StageTrace::read(path).empty());  // gone: nothing to read
}

TEST(StageTrace, LoopMarksReadBackBesideTheRecordsUpToCapacity) {
  StageTrace t(2);
  t.mark("woke", '.');
  t.mark("flush", 'b');
  t.mark("flush", 'e');  // over capacity: left out
  ASSERT_EQ(t.marks().size(), 2U);
  EXPECT_LE(t.marks()[0].ns, t.marks()[1].ns);
  const std::string path = ::testing::TempDir() + "stage_trace_marks_" + std::to_string(::getpid()) + ".tsv";
  ASSERT_TRUE(t.write(path));
  const auto back = StageTrace::read_marks(path);
  std::remove(path.c_str());
  std::remove((path + ".loop").c_str());
  ASSERT_EQ(back.size(), 2U);
  EXPECT_EQ(back[1].ns, t.marks()[1].ns);
  EXPECT_EQ(back[1].what, "flush");
  EXPECT_EQ(back[1].phase, 'b');
  EXPECT_TRUE(StageTrace::read_marks(path).empty());
}

}  // namespace
}  // namespace rigger::task_controller
