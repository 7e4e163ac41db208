// Two-phase shutdown, its races, stop timeouts, cancel, pause and resume.

#include <gtest/gtest.h>

#include "fake_port.hpp"

namespace rigger::bt {
namespace {

using namespace build;
using testing::Harness;

Node paper_parallel() {
  auto attach = skill("AttachRobotToLoad", {"robot", "gripper"});
  attach.stop_timeout_s = 2.0;
  return parallel(1, 1, {attach, monitor("YankMonitor")});
}

TEST(EngineShutdown, ParentWaitsForEveryShutDownChild) {
  Harness h(sequence({paper_parallel(), skill("Next")}));
  h.engine->start();
  h.fail("root/0/1", "YANK");
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/0"), NodeState::kRunning);
  EXPECT_EQ(h.state("root"), NodeState::kRunning);
  h.advance(1.0);
  EXPECT_EQ(h.state("root/0"), NodeState::kRunning);
  h.stopped("root/0/0");
  EXPECT_EQ(h.state("root/0"), NodeState::kFailure);
  EXPECT_EQ(h.port.result()->code, "YANK");
  EXPECT_EQ(h.state("root/1"), NodeState::kIdle);
  EXPECT_EQ(h.port.count("start root/1"), 0U);
}

TEST(EngineShutdown, NextSiblingStartsOnlyAfterStop) {
  Harness h(sequence({paper_parallel(), skill("Next")}));
  h.engine->start();
  h.succeed("root/0/0");  // the skill succeeds; the monitor must be shut down first
  EXPECT_EQ(h.state("root/0/1"), NodeState::kStopping);
  EXPECT_EQ(h.port.count("start root/1"), 0U);
  h.stopped("root/0/1");
  EXPECT_EQ(h.port.count("start root/1"), 1U);
  EXPECT_LT(h.port.position("state root/0/1 STOPPED"), h.port.position("start root/1"));
}

TEST(EngineShutdown, EventArrivingWhileStoppingCountsAsStopped) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  ASSERT_EQ(h.state("root/0"), NodeState::kStopping);
  // The skill's SUCCESS crossed the SHUTDOWN on the wire.
  const auto r = h.succeed("root/0");
  EXPECT_EQ(r.status, EventStatus::kAccepted);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.status("root/0").code, codes::kFinishedWhileStopping);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, "YANK");
  // The executor's STOPPED for the same activation is then a duplicate and changes nothing.
  EXPECT_EQ(h.stopped("root/0").status, EventStatus::kNotActive);
  EXPECT_EQ(h.port.finished_count(), 1);
}

TEST(EngineShutdown, FailureWhileStoppingCountsAsStopped) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  EXPECT_EQ(h.fail("root/0", "INTERRUPTED").status, EventStatus::kAccepted);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.port.result()->code, "YANK");
}

TEST(EngineShutdown, ProgressWhileStoppingIsAccepted) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  EXPECT_EQ(h.leaf("root/0", LeafEventKind::kProgress).status, EventStatus::kAccepted);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
}

TEST(EngineShutdown, StopTimeoutEscalatesSafeStopAndCountsAsStopped) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  h.advance(1.9);
  EXPECT_TRUE(h.port.escalations().empty());
  EXPECT_EQ(h.state("root"), NodeState::kRunning);
  h.advance(0.2);
  EXPECT_EQ(h.port.escalations(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.status("root/0").code, codes::kStopTimeout);
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->code, "YANK");
  EXPECT_EQ(h.port.result()->escalated, std::vector<std::string>{"root/0"});
  EXPECT_LT(h.port.position("escalate root/0"), h.port.position("state root FAILURE"));
}

// The skill says its own safe stop failed while it was being stopped: its devices may still move, so the
// engine escalates at once instead of filing the FAILURE as FINISHED_WHILE_STOPPING.
TEST(EngineShutdown, AFailedSafeStopWhileStoppingIsEscalated) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
  h.fail("root/0", codes::kSafeStopFailed);
  EXPECT_EQ(h.port.escalations(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.status("root/0").code, codes::kSafeStopFailed);
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->escalated, std::vector<std::string>{"root/0"});
}

// Any other FAILURE while stopping raced the SHUTDOWN: no escalation.
TEST(EngineShutdown, AnOrdinaryFailureWhileStoppingIsNotEscalated) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  h.fail("root/0", "GRIP_LOST");
  EXPECT_TRUE(h.port.escalations().empty());
  EXPECT_EQ(h.status("root/0").code, codes::kFinishedWhileStopping);
}

TEST(EngineShutdown, StoppedAfterStopTimeoutIsRejectedAsLate) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  h.advance(3.0);
  const auto r = h.stopped("root/0");
  EXPECT_EQ(r.status, EventStatus::kNotActive);
  EXPECT_NE(r.reason.find("after the stop timeout"), std::string::npos);
  EXPECT_EQ(h.port.finished_count(), 1);
}

TEST(EngineShutdown, StopAcknowledgedInTimeCancelsItsTimer) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  EXPECT_EQ(h.port.timers().size(), 1U);
  h.stopped("root/0");
  EXPECT_TRUE(h.port.timers().empty());
  h.advance(10.0);
  EXPECT_TRUE(h.port.escalations().empty());
}

TEST(EngineShutdown, NestedCompositesStopBottomUp) {
  Harness h(parallel(1, 1, {sequence({parallel(1, 1, {skill("A"), skill("B")}), skill("C")}), monitor("M")}));
  h.engine->start();
  h.fail("root/1", "FIRED");
  EXPECT_EQ(h.state("root/0/0/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/0/0/1"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
  h.stopped("root/0/0/0");
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopping);
  h.stopped("root/0/0/1");
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopped);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.state("root/0/1"), NodeState::kIdle);  // never started
  EXPECT_EQ(h.port.result()->code, "FIRED");
}

TEST(EngineShutdown, RunningConditionStopsImmediatelyAndLateAnswerIsRejected) {
  Harness h(parallel(1, 1, {condition("ObjectLocalized"), monitor("M")}));
  h.engine->start();
  h.fail("root/1");
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.condition("root/0", true).status, EventStatus::kNotActive);
}

TEST(EngineShutdown, TimeoutDeadlineWhileChildIsStoppingForAnotherReason) {
  // The parallel decides (monitor fired), the Timeout around the skill is shut down; its deadline
  // timer must be cancelled so that it does not fire into the stopping subtree.
  auto slow = skill("Slow");
  slow.stop_timeout_s = 30.0;
  Harness h(parallel(1, 1, {timeout(5.0, slow), monitor("M")}));
  h.engine->start();
  h.fail("root/1");
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
  EXPECT_EQ(h.port.timers().size(), 1U);  // only the stop timer of the skill
  h.advance(10.0);
  EXPECT_EQ(h.status("root/0").code, "");
  h.stopped("root/0/0");
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
}

TEST(EngineExecutorLost, RunningLeafFailsAndSiblingsStop) {
  Harness h(paper_parallel());
  h.engine->start();
  const auto r = h.engine->on_leaf_lost("root/0", h.act("root/0"), "liveliness lost");
  EXPECT_EQ(r.status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.escalations(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.state("root/0"), NodeState::kFailure);
  EXPECT_EQ(h.status("root/0").code, codes::kExecutorLost);
  EXPECT_EQ(h.state("root/1"), NodeState::kStopping);
  h.stopped("root/1");
  EXPECT_EQ(h.port.result()->code, codes::kExecutorLost);
  EXPECT_EQ(h.port.result()->origin, "root/0");
  EXPECT_EQ(h.port.result()->escalated, std::vector<std::string>{"root/0"});
}

TEST(EngineExecutorLost, WhileStoppingEscalatesAtOnce) {
  Harness h(paper_parallel());
  h.engine->start();
  h.fail("root/1", "YANK");
  ASSERT_EQ(h.state("root/0"), NodeState::kStopping);
  h.engine->on_leaf_lost("root/0", h.act("root/0"), "process died");
  EXPECT_EQ(h.port.escalations(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.status("root/0").code, codes::kExecutorLost);
  EXPECT_TRUE(h.port.timers().empty());  // the stop timer is cancelled
  EXPECT_EQ(h.port.result()->code, "YANK");
}

TEST(EngineExecutorLost, AfterTheLeafFinishedIsRejected) {
  Harness h(sequence({skill("A"), skill("B")}));
  h.engine->start();
  h.succeed("root/0");
  EXPECT_EQ(h.engine->on_leaf_lost("root/0", 1, "gone").status, EventStatus::kNotActive);
  EXPECT_EQ(h.engine->on_leaf_lost("root", 1, "gone").status, EventStatus::kWrongKind);
  EXPECT_TRUE(h.port.escalations().empty());
}

TEST(EngineCancel, ShutsDownTheWholeTreeAndFinishesCanceled) {
  Harness h(sequence({paper_parallel(), skill("Next")}));
  h.engine->start();
  EXPECT_EQ(h.engine->cancel("operator pressed stop").status, EventStatus::kAccepted);
  EXPECT_TRUE(h.engine->canceling());
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/0/1"), NodeState::kStopping);
  EXPECT_NE(h.port.last_shutdown_reason().find("operator pressed stop"), std::string::npos);
  EXPECT_FALSE(h.port.result());
  h.stop_all_stopping();
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
  EXPECT_EQ(h.port.result()->code, codes::kCanceled);
  EXPECT_EQ(h.port.result()->message, "operator pressed stop");
  EXPECT_EQ(h.state("root"), NodeState::kStopped);
  EXPECT_EQ(h.port.count("start root/1"), 0U);
}

TEST(EngineCancel, SecondCancelIsRefusedAndEventsStillHonoured) {
  Harness h(skill("A"));
  h.engine->start();
  h.engine->cancel("first");
  EXPECT_EQ(h.engine->cancel("second").status, EventStatus::kWrongPhase);
  h.stopped("root");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
}

TEST(EngineCancel, BeforeStartFinishesAtOnceWithoutStartingAnything) {
  Harness h(skill("A"));
  EXPECT_EQ(h.engine->cancel("changed my mind").status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
  EXPECT_EQ(h.engine->start().status, EventStatus::kWrongPhase);
  EXPECT_TRUE(h.port.starts().empty());
}

TEST(EngineCancel, WhileAwaitingOperatorWithdrawsQuestion) {
  Harness h(decision("?", {{"a", skill("A")}}));
  h.engine->start();
  h.engine->cancel("bye");
  EXPECT_EQ(h.port.count("withdraw root"), 1U);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
}

TEST(EngineCancel, StopTimeoutDuringCancelEscalates) {
  Harness h(paper_parallel());
  h.engine->start();
  h.engine->cancel("stop");
  h.stopped("root/1");
  h.advance(5.0);
  EXPECT_EQ(h.port.escalations(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
  EXPECT_EQ(h.port.result()->escalated, std::vector<std::string>{"root/0"});
}

TEST(EngineCancel, DuringDecidedParallelStillWaitsForChildren) {
  Harness h(paper_parallel());
  h.engine->start();
  h.succeed("root/0");
  ASSERT_EQ(h.state("root/1"), NodeState::kStopping);
  h.engine->cancel("now");
  EXPECT_EQ(h.state("root"), NodeState::kStopping);
  EXPECT_FALSE(h.port.result());
  h.stopped("root/1");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
}

TEST(EnginePause, NoNewNodeStartsWhilePaused) {
  Harness h(sequence({skill("A"), skill("B")}));
  h.engine->start();
  EXPECT_EQ(h.engine->pause().status, EventStatus::kAccepted);
  EXPECT_EQ(h.engine->pause().status, EventStatus::kWrongPhase);
  // A keeps running while paused and may finish.
  EXPECT_EQ(h.succeed("root/0").status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.count("start root/1"), 0U);
  EXPECT_EQ(h.state("root/1"), NodeState::kIdle);
  EXPECT_EQ(h.engine->resume().status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.count("start root/1"), 1U);
  EXPECT_EQ(h.engine->resume().status, EventStatus::kWrongPhase);
  h.succeed("root/1");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EnginePause, PauseBeforeStartHoldsTheRoot) {
  Harness h(parallel(1, 1, {skill("A"), monitor("M")}));
  h.engine->pause();
  h.engine->start();
  EXPECT_TRUE(h.port.starts().empty());
  h.engine->resume();
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/0", "root/1"}));
}

TEST(EnginePause, HeldStartsRunInRequestOrder) {
  Harness h(parallel(2, 1, {sequence({skill("A"), skill("B")}), sequence({skill("C"), skill("D")})}));
  h.engine->start();
  h.engine->pause();
  h.succeed("root/1/0");
  h.succeed("root/0/0");
  EXPECT_EQ(h.port.starts().size(), 2U);
  h.engine->resume();
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/0/0", "root/1/0", "root/1/1", "root/0/1"}));
}

TEST(EnginePause, RetryAndOperatorBranchWaitForResume) {
  Harness h(sequence({retry(2, skill("A")), decision("?", {{"x", skill("X")}})}));
  h.engine->start();
  h.engine->pause();
  h.fail("root/0/0");
  EXPECT_EQ(h.state("root/0/0"), NodeState::kFailure);
  EXPECT_EQ(h.port.starts().size(), 1U);
  h.engine->resume();
  EXPECT_EQ(h.act("root/0/0"), 2U);
  h.succeed("root/0/0");
  EXPECT_EQ(h.port.log().back(), "ask root/1");
  h.engine->pause();
  EXPECT_EQ(h.decide("root/1", 0).status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.count("start root/1/0"), 0U);
  h.engine->resume();
  EXPECT_EQ(h.port.count("start root/1/0"), 1U);
}

TEST(EnginePause, CancelWhilePausedDropsHeldStarts) {
  Harness h(sequence({skill("A"), skill("B")}));
  h.engine->start();
  h.engine->pause();
  h.succeed("root/0");
  h.engine->cancel("abort");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kCanceled);
  h.engine->resume();
  EXPECT_EQ(h.port.count("start root/1"), 0U);
}

TEST(EnginePause, ParallelDecisionWhilePausedDropsHeldSiblingStarts) {
  Harness h(parallel(1, 1, {monitor("M"), sequence({skill("A"), skill("B")})}));
  h.engine->start();
  h.engine->pause();
  h.succeed("root/1/0");  // B's start is held
  h.fail("root/0", "FIRED");
  EXPECT_EQ(h.port.result()->code, "FIRED");
  h.engine->resume();
  EXPECT_EQ(h.port.count("start root/1/1"), 0U);
}

TEST(EnginePause, PausedTimeoutStillEnforcesItsDeadline) {
  Harness h(timeout(2.0, skill("A")));
  h.engine->start();
  h.engine->pause();
  h.advance(2.5);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
  h.stopped("root/0");
  EXPECT_EQ(h.port.result()->code, codes::kTimeout);
}

TEST(EngineStatus, TimestampsComeFromThePortClock) {
  Harness h(skill("A"));
  h.engine->start();
  const auto started = *h.status("root").started_at;
  h.advance(3.0);
  h.succeed("root");
  EXPECT_EQ(*h.status("root").finished_at - started, std::chrono::duration_cast<Clock::duration>(Seconds(3.0)));
}

}  // namespace
}  // namespace rigger::bt
