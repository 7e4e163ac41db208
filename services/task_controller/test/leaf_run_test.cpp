// What an executor's event means for the controller: which run it is for, what the engine makes of it.

#include "leaf_run.hpp"

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

TEST(MatchRun, TellsCurrentUnknownAndStale) {
  const LeafRun run{{"exec-a", 7, false}, 2};
  EXPECT_EQ(match_run(&run, "exec-a", 7), RunMatch::kCurrent);
  EXPECT_EQ(match_run(&run, "exec-a", 6), RunMatch::kStale);
  EXPECT_EQ(match_run(&run, "exec-a", 8), RunMatch::kStale);
  EXPECT_EQ(match_run(&run, "exec-b", 7), RunMatch::kUnknown);
  EXPECT_EQ(match_run(nullptr, "exec-a", 7), RunMatch::kUnknown);
}

TEST(ToLeafEvent, MapsKindsAndKeepsTheProtocolsOwnAnswersFromTheEngine) {
  using skill_protocol::EventKind;
  auto ev = to_leaf_event({EventKind::kFailure, "YANK_DETECTED", "yank 900 N/s", std::nullopt});
  EXPECT_EQ(ev.kind, bt::LeafEventKind::kFailure);
  EXPECT_EQ(ev.code, "YANK_DETECTED");
  EXPECT_EQ(ev.message, "yank 900 N/s");
  EXPECT_EQ(to_leaf_event({EventKind::kSuccess, "", "", std::nullopt}).kind, bt::LeafEventKind::kSuccess);
  EXPECT_EQ(to_leaf_event({EventKind::kStopped, "", "", std::nullopt}).kind, bt::LeafEventKind::kStopped);
  ev = to_leaf_event({EventKind::kProgress, "", "", 0.5});
  EXPECT_EQ(ev.kind, bt::LeafEventKind::kProgress);
  ASSERT_TRUE(ev.progress);
  EXPECT_DOUBLE_EQ(*ev.progress, 0.5);
  for (EventKind answer : {EventKind::kAccepted, EventKind::kPaused, EventKind::kResumed}) {
    ev = to_leaf_event({answer, "WAITING", "", 0.5});
    EXPECT_EQ(ev.kind, bt::LeafEventKind::kProgress) << skill_protocol::to_string(answer);
    EXPECT_FALSE(ev.progress) << skill_protocol::to_string(answer);
  }
}

}  // namespace
}  // namespace rigger::task_controller
