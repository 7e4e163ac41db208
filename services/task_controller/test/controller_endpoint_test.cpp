// The controller's half of the skill protocol, its pure rules: event order per writer, run matching,
// an outcome as the engine's.

#include "controller_endpoint.hpp"

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

TEST(EventOrder, AcceptsOnlyNewerSeqsPerWriter) {
  EventOrder order;
  std::uint64_t last = 99;
  EXPECT_TRUE(order.accept(1, 1, &last));
  EXPECT_EQ(last, 0U);
  EXPECT_TRUE(order.accept(1, 5, &last));
  EXPECT_EQ(last, 1U);
  EXPECT_FALSE(order.accept(1, 5, &last)) << "duplicate";
  EXPECT_EQ(last, 5U);
  EXPECT_FALSE(order.accept(1, 3, &last)) << "out of order";
  EXPECT_EQ(last, 5U) << "a rejected seq does not move the last one";
  EXPECT_TRUE(order.accept(2, 1)) << "another writer counts on its own";
  EXPECT_FALSE(order.accept(1, 0)) << "seq 0 is never newer";
}

TEST(MatchRun, TellsCurrentUnknownAndStale) {
  const LeafRun run{"exec-a", 7, 2};
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
