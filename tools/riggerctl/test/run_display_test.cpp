#include "run_display.hpp"

#include <gtest/gtest.h>

namespace rigger::ctl {
namespace {

NodeUpdate node(const std::string& id, const std::string& type, const std::string& name, const std::string& state,
                double started, double finished = 0.0) {
  NodeUpdate n;
  n.id = id;
  n.type = type;
  n.name = name;
  n.state = state;
  n.started_s = started;
  n.finished_s = finished;
  return n;
}

TEST(RunDisplay, TreeOrderIsNumericPerLevelAndParentsFirst) {
  EXPECT_TRUE(tree_order_less("root/0/9", "root/0/10"));
  EXPECT_FALSE(tree_order_less("root/0/10", "root/0/9"));
  EXPECT_TRUE(tree_order_less("root/0", "root/0/0"));
  EXPECT_TRUE(tree_order_less("root", "root/1"));
  EXPECT_FALSE(tree_order_less("root/1", "root/1"));
}

TEST(RunDisplay, LinePerChangeWithoutATerminal) {
  RunDisplay d(false);
  const std::string text = d.update(node("root/1", "Skill", "attach", "RUNNING", 100.0));
  EXPECT_EQ(text, "  root/1 Skill \"attach\"  RUNNING\n");
}

TEST(RunDisplay, RedrawMovesBackOverTheLinesDrawnBefore) {
  RunDisplay d(true);
  const std::string first = d.update(node("root", "Sequence", "", "RUNNING", 100.0));
  EXPECT_EQ(first.find("\x1b[1F"), std::string::npos);  // nothing drawn before
  const std::string second = d.update(node("root/0", "Skill", "a", "RUNNING", 100.5));
  EXPECT_EQ(second.rfind("\x1b[1F", 0), 0U) << "moves up over the one line drawn";
  EXPECT_NE(second.find("root/0 Skill"), std::string::npos);
  EXPECT_LT(second.find("root Sequence"), second.find("root/0 Skill")) << "tree order";
}

TEST(RunDisplay, DurationsListSkillsInStartOrderWithRetries) {
  RunDisplay d(false);
  d.update(node("root/1", "Skill", "second", "RUNNING", 110.0));
  d.update(node("root/1", "Skill", "second", "SUCCESS", 110.0, 112.5));
  d.update(node("root/0", "Skill", "first", "RUNNING", 100.0));
  d.update(node("root/0", "Skill", "first", "FAILURE", 100.0, 101.0));
  d.update(node("root/0", "Skill", "first", "RUNNING", 103.0));
  d.update(node("root/0", "Skill", "first", "RUNNING", 103.0001));  // progress; the start time jitters
  d.update(node("root/0", "Skill", "first", "SUCCESS", 103.0002, 107.0));
  d.update(node("root/2", "Monitor", "watch", "STOPPED", 100.0, 107.0));
  const std::string report = d.durations(12.5);
  const auto first = report.find("first");
  const auto second = report.find("second");
  ASSERT_NE(first, std::string::npos);
  ASSERT_NE(second, std::string::npos);
  EXPECT_LT(first, second) << report;
  EXPECT_NE(report.find("4.0 s  (2 runs, 5.0 s in all)"), std::string::npos) << report;
  EXPECT_NE(report.find("2.5 s"), std::string::npos) << report;
  EXPECT_EQ(report.find("second  SUCCESS    2.5 s  ("), std::string::npos) << "one run: no run count";
  EXPECT_EQ(report.find("watch"), std::string::npos) << "monitors are not skills";
  EXPECT_NE(report.find("wall time of the task: 12.5 s"), std::string::npos);
}

}  // namespace
}  // namespace rigger::ctl
