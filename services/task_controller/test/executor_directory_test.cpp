// ExecutorDirectory: which executor runs a leaf, liveliness, and the library recipes are checked against.

#include "executor_directory.hpp"

#include <set>

#include <gtest/gtest.h>

#include "unit_test_util.hpp"

namespace rigger::task_controller {
namespace {

using testing::library_with;

TEST(ExecutorDirectory, PicksTheFirstLiveExecutorOfferingTheSkill) {
  ExecutorDirectory d;
  d.announce("b-exec", true, library_with({"Pick"}).dump(), {"Pick"});
  d.announce("a-exec", true, library_with({"Pick", "Localize"}).dump(), {"Pick", "Localize"});
  EXPECT_EQ(d.pick("Pick", ""), "a-exec");  // by id
  EXPECT_EQ(d.pick("Localize", ""), "a-exec");
  EXPECT_EQ(d.pick("Place", ""), "");
  d.gone("a-exec");
  EXPECT_EQ(d.pick("Pick", ""), "b-exec");
  EXPECT_EQ(d.pick("Localize", ""), "");
}

TEST(ExecutorDirectory, APinnedExecutorIsTheOnlyChoice) {
  ExecutorDirectory d;
  d.announce("a-exec", true, library_with({"Pick"}).dump(), {"Pick"});
  d.announce("b-exec", true, library_with({"Pick"}).dump(), {"Pick"});
  EXPECT_EQ(d.pick("Pick", "b-exec"), "b-exec");
  EXPECT_EQ(d.pick("Pick", "c-exec"), "") << "an unknown pinned executor is no executor";
  EXPECT_EQ(d.pick("Place", "b-exec"), "") << "the pinned executor does not offer the skill";
  d.announce("b-exec", false, library_with({"Pick"}).dump(), {"Pick"});
  EXPECT_EQ(d.pick("Pick", "b-exec"), "") << "a dead pinned executor is not replaced by another";
}

TEST(ExecutorDirectory, ReportsUpLostAndGoneOnce) {
  ExecutorDirectory d;
  auto c = d.announce("x", true, "{}", {});
  EXPECT_TRUE(c.alive);
  EXPECT_TRUE(c.came_up);
  EXPECT_FALSE(c.lost);
  c = d.announce("x", true, "{}", {});
  EXPECT_FALSE(c.came_up) << "a repeated announcement is not a new executor";
  EXPECT_TRUE(d.alive("x"));
  EXPECT_TRUE(d.gone("x"));
  EXPECT_FALSE(d.gone("x")) << "lost once";
  EXPECT_FALSE(d.gone("never-seen"));
  c = d.announce("x", false, "{}", {});
  EXPECT_FALSE(c.lost) << "it was already lost";
  d.announce("y", true, "{}", {});
  c = d.announce("y", false, "{}", {});
  EXPECT_TRUE(c.lost);
  EXPECT_FALSE(d.alive("y"));
}

TEST(ExecutorDirectory, LiveLibraryMergesLiveExecutorsAndTheControllersConditions) {
  ExecutorDirectory d;
  d.announce("a", true, library_with({"Pick"}).dump(), {"Pick"});
  d.announce("b", true, library_with({"Localize"}).dump(), {"Localize"});
  d.announce("dead", true, library_with({"Place"}).dump(), {"Place"});
  d.gone("dead");
  std::vector<std::string> problems;
  const auto library = d.live_library(&problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_NE(library.find("Pick"), nullptr);
  EXPECT_NE(library.find("Localize"), nullptr);
  EXPECT_EQ(library.find("Place"), nullptr) << "a dead executor's skills are not offered";
  EXPECT_NE(library.find("ObjectLocalized"), nullptr) << "the controller answers this condition itself";
}

// Announcements come from other processes: their bounds are enforced while parsing.
TEST(ExecutorDirectory, AnOversizedOrTooDeepAnnouncementIsRefusedWhileParsing) {
  ExecutorDirectory d;
  const auto deep = d.announce("deep", true, std::string(100000, '[') + std::string(100000, ']'), {"Pick"});
  EXPECT_NE(deep.library_error.find("nesting deeper"), std::string::npos) << deep.library_error;
  const auto big = d.announce("big", true, "\"" + std::string(2U * 1024U * 1024U, 'x') + "\"", {"Pick"});
  EXPECT_FALSE(big.library_error.empty());
  std::vector<std::string> problems;
  d.live_library(&problems);
  EXPECT_TRUE(problems.empty()) << "refused announcements offer no library at all";
}

TEST(ExecutorDirectory, AnUnreadableOrInvalidLibraryIsReportedAndSkipped) {
  ExecutorDirectory d;
  const auto c = d.announce("bad-json", true, "{not json", {"Pick"});
  EXPECT_FALSE(c.library_error.empty());
  d.announce("bad-library", true, R"({"library_version": 1, "skills": [{"name": 3}]})", {"Pick"});
  d.announce("good", true, library_with({"Localize"}).dump(), {"Localize"});
  std::vector<std::string> problems;
  const auto library = d.live_library(&problems);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_NE(problems[0].find("executor library invalid executor=bad-library"), std::string::npos) << problems[0];
  EXPECT_NE(library.find("Localize"), nullptr);
  EXPECT_EQ(library.find("Pick"), nullptr);
  EXPECT_EQ(d.pick("Pick", ""), "bad-json") << "what an executor offers is its skills list, not its library";
}

TEST(ExecutorDirectory, AnUnchangedReannouncementKeepsTheParsedLibraryAndAChangedOneReplacesIt) {
  ExecutorDirectory d;
  EXPECT_FALSE(d.announce("bad", true, "{not json", {"Pick"}).library_error.empty());
  EXPECT_TRUE(d.announce("bad", true, "{not json", {"Pick"}).library_error.empty()) << "reported once per text";
  const std::string localize = library_with({"Localize"}).dump();
  d.announce("ex", true, localize, {"Localize"});
  d.announce("ex", true, localize, {"Localize"});
  EXPECT_NE(d.live_library().find("Localize"), nullptr);
  d.announce("ex", true, library_with({"Pick"}).dump(), {"Pick"});
  const auto library = d.live_library();
  EXPECT_EQ(library.find("Localize"), nullptr);
  EXPECT_NE(library.find("Pick"), nullptr);
  d.announce("ex", true, "", {"Pick"});
  EXPECT_EQ(d.live_library().find("Pick"), nullptr) << "an empty text announces no library";
}

// A restarted controller learns from the announcements which runs of its predecessor still hold
// resources, and starts nothing on them until they are free.
TEST(ExecutorDirectory, ARunOfAnotherTaskHoldsItsResourcesUntilItIsAnnouncedEnded) {
  using skill_protocol::AnnouncedRun;
  ExecutorDirectory d;
  const std::string lib = library_with({"Pick", "Localize"}).dump();
  const AnnouncedRun old_pick{"old", "root/0", "Pick", {"robot", "gripper"}, true};
  auto c = d.announce("a", true, lib, {"Pick", "Localize"}, {old_pick});
  EXPECT_TRUE(c.runs_changed);
  d.announce("b", true, lib, {"Pick"}, {{"new", "root/1", "Localize", {"camera"}, false}});

  auto h = d.holder({"gripper", "robot"}, "new");
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->executor_id, "a");
  EXPECT_EQ(h->resource, "gripper") << "the START's first resource the run holds";
  EXPECT_EQ(h->run, old_pick);
  EXPECT_EQ(h->describe(), "resource 'gripper', held by Pick (task old, node root/0) on executor a, stopping");
  EXPECT_FALSE(d.holder({"camera"}, "new").has_value()) << "a task's own runs are the executor's to order";
  EXPECT_FALSE(d.holder({"crane"}, "new").has_value()) << "nobody holds the crane";
  EXPECT_TRUE(d.holder({"camera"}, "other").has_value());
  EXPECT_FALSE(d.holder({}, "new").has_value()) << "a leaf that claims nothing is never held";
  // A resumed task: its runs hold unless this controller started them (the killed controller's do).
  const std::set<std::string> none, started{"root/1"};
  EXPECT_TRUE(d.holder({"camera"}, "new", &none).has_value());
  EXPECT_FALSE(d.holder({"camera"}, "new", &started).has_value());
  // A resumed task's START of a node that claims nothing waits while the killed controller's run of that
  // very node still runs (the executor would refuse it ALREADY_RUNNING); another node's does not.
  const auto own = d.holder({}, "new", &none, "root/1");
  ASSERT_TRUE(own.has_value());
  EXPECT_EQ(own->describe(), "its own earlier run, Localize (task new, node root/1) on executor b, running");
  EXPECT_FALSE(d.holder({}, "new", &none, "root/2").has_value());
  EXPECT_FALSE(d.holder({}, "new", &started, "root/1").has_value()) << "this controller's own run";
  EXPECT_FALSE(d.holder({}, "new", nullptr, "root/1").has_value()) << "not resumed: the executor orders its runs";

  c = d.announce("a", true, lib, {"Pick", "Localize"}, {old_pick});
  EXPECT_FALSE(c.runs_changed) << "a re-announcement of the same runs changes nothing";
  c = d.announce("a", true, lib, {"Pick", "Localize"}, {});
  EXPECT_TRUE(c.runs_changed);
  EXPECT_FALSE(d.holder({"robot"}, "new").has_value()) << "the run ended: its resources are free";
}

TEST(ExecutorDirectory, ALostExecutorHoldsNothing) {
  ExecutorDirectory d;
  d.announce("a", true, library_with({"Pick"}).dump(), {"Pick"}, {{"old", "root", "Pick", {"robot"}, false}});
  ASSERT_TRUE(d.holder({"robot"}, "new").has_value());
  EXPECT_EQ(d.holder({"robot"}, "new")->describe(),
            "resource 'robot', held by Pick (task old, node root) on executor a, running");
  d.gone("a");
  EXPECT_FALSE(d.holder({"robot"}, "new").has_value())
      << "its runs are lost with it (their leaves fail EXECUTOR_LOST, the safe stop is escalated)";
}

}  // namespace
}  // namespace rigger::task_controller
