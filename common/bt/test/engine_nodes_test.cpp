// Semantics of every node type, and the engine's refusal of inputs that do not fit.

#include <gtest/gtest.h>

#include "fake_port.hpp"

namespace rigger::bt {
namespace {

using namespace build;
using testing::Harness;

// --- Leaves -----------------------------------------------------------------------------------

TEST(EngineLeaf, SkillSuccessFinishesTask) {
  Harness h(skill("Pick"));
  EXPECT_EQ(h.engine->start().status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root"});
  EXPECT_EQ(h.state("root"), NodeState::kRunning);
  EXPECT_EQ(h.act("root"), 1U);
  EXPECT_FALSE(h.port.result());
  EXPECT_EQ(h.succeed("root").status, EventStatus::kAccepted);
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_EQ(h.port.finished_count(), 1);
  EXPECT_EQ(h.engine->result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_TRUE(h.status("root").finished_at.has_value());
}

TEST(EngineLeaf, SkillFailureCarriesCodeMessageAndOrigin) {
  Harness h(skill("Pick"));
  h.engine->start();
  h.fail("root", "GRASP_FAILED");
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, "GRASP_FAILED");
  EXPECT_EQ(h.port.result()->message, "because GRASP_FAILED");
  EXPECT_EQ(h.port.result()->origin, "root");
}

TEST(EngineLeaf, FailureWithoutCodeGetsDefault) {
  Harness h(skill("Pick"));
  h.engine->start();
  LeafEvent e;
  e.kind = LeafEventKind::kFailure;
  e.activation = 1;
  h.engine->on_leaf_event("root", e);
  EXPECT_EQ(h.port.result()->code, codes::kFailed);
}

TEST(EngineLeaf, ProgressUpdatesStatusButNotState) {
  Harness h(skill("Pick"));
  h.engine->start();
  LeafEvent e;
  e.kind = LeafEventKind::kProgress;
  e.activation = 1;
  e.progress = 0.4;
  e.message = "approaching";
  const auto changes = h.port.changes();
  EXPECT_EQ(h.engine->on_leaf_event("root", e).status, EventStatus::kAccepted);
  EXPECT_EQ(h.state("root"), NodeState::kRunning);
  EXPECT_EQ(h.status("root").progress, 0.4);
  EXPECT_EQ(h.status("root").message, "approaching");
  EXPECT_EQ(h.port.changes(), changes + 1);
  e.progress = 1.5;
  EXPECT_EQ(h.engine->on_leaf_event("root", e).status, EventStatus::kInvalidArgument);
  e.progress = -0.1;
  EXPECT_EQ(h.engine->on_leaf_event("root", e).status, EventStatus::kInvalidArgument);
  EXPECT_EQ(h.status("root").progress, 0.4);
}

TEST(EngineLeaf, MonitorSuccessIsProtocolErrorTreatedAsFailure) {
  Harness h(monitor("YankMonitor"));
  h.engine->start();
  const auto r = h.succeed("root");
  EXPECT_EQ(r.status, EventStatus::kProtocolError);
  EXPECT_TRUE(r.acted_on());
  EXPECT_NE(r.reason.find("never succeed"), std::string::npos);
  EXPECT_EQ(h.state("root"), NodeState::kFailure);
  EXPECT_EQ(h.status("root").code, codes::kProtocolError);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, codes::kProtocolError);
}

TEST(EngineLeaf, MonitorFailureFailsTask) {
  Harness h(monitor("ForceMonitor"));
  h.engine->start();
  h.fail("root", "FORCE_LIMIT");
  EXPECT_EQ(h.port.result()->code, "FORCE_LIMIT");
}

TEST(EngineLeaf, ConditionTrueAndFalse) {
  {
    Harness h(condition("ObjectLocalized"));
    h.engine->start();
    EXPECT_EQ(h.port.log().back(), "evaluate root");
    EXPECT_EQ(h.condition("root", true).status, EventStatus::kAccepted);
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  }
  {
    Harness h(condition("ObjectLocalized"));
    h.engine->start();
    h.condition("root", false);
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
    EXPECT_EQ(h.port.result()->code, codes::kConditionFalse);
  }
  {
    Harness h(condition("ObjectLocalized"));
    h.engine->start();
    h.engine->on_condition_result("root", 1, false, "TOO_OLD", "pose is 9 s old");
    EXPECT_EQ(h.port.result()->code, "TOO_OLD");
    EXPECT_EQ(h.port.result()->message, "pose is 9 s old");
  }
}

// --- Sequence and Fallback ------------------------------------------------------------------

TEST(EngineSequence, StartsChildrenOneAfterAnother) {
  Harness h(sequence({skill("A"), skill("B"), skill("C")}));
  h.engine->start();
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/0"});
  h.succeed("root/0");
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/0", "root/1"}));
  EXPECT_EQ(h.state("root/2"), NodeState::kIdle);
  h.succeed("root/1");
  h.succeed("root/2");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_EQ(h.state("root"), NodeState::kSuccess);
  // The child reported before its parent did.
  EXPECT_LT(h.port.position("state root/2 SUCCESS"), h.port.position("state root SUCCESS"));
}

TEST(EngineSequence, FirstFailureFailsAndLaterChildrenNeverStart) {
  Harness h(sequence({skill("A"), skill("B"), skill("C")}));
  h.engine->start();
  h.succeed("root/0");
  h.fail("root/1", "B_BROKE");
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/0", "root/1"}));
  EXPECT_EQ(h.state("root/2"), NodeState::kIdle);
  EXPECT_EQ(h.port.result()->code, "B_BROKE");
  EXPECT_EQ(h.port.result()->origin, "root/1");
}

TEST(EngineFallback, FirstSuccessSucceeds) {
  Harness h(fallback({skill("A"), skill("B"), skill("C")}));
  h.engine->start();
  h.fail("root/0");
  EXPECT_EQ(h.port.starts().back(), "root/1");
  h.succeed("root/1");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_EQ(h.state("root/2"), NodeState::kIdle);
}

TEST(EngineFallback, AllFailFailsWithLastReason) {
  Harness h(fallback({skill("A"), skill("B")}));
  h.engine->start();
  h.fail("root/0", "FIRST");
  h.fail("root/1", "SECOND");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, "SECOND");
  EXPECT_EQ(h.port.result()->origin, "root/1");
  EXPECT_NE(h.port.result()->message.find("all 2 alternatives failed"), std::string::npos);
}

TEST(EngineSequence, NestedOriginPropagatesToRoot) {
  Harness h(sequence({fallback({skill("A"), sequence({skill("B"), skill("C")})})}));
  h.engine->start();
  h.fail("root/0/0");
  h.succeed("root/0/1/0");
  h.fail("root/0/1/1", "DEEP");
  EXPECT_EQ(h.port.result()->code, "DEEP");
  EXPECT_EQ(h.port.result()->origin, "root/0/1/1");
}

// --- Decorators -------------------------------------------------------------------------------

TEST(EngineInverter, SwapsResults) {
  {
    Harness h(inverter(skill("A")));
    h.engine->start();
    h.succeed("root/0");
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
    EXPECT_EQ(h.port.result()->code, codes::kInverted);
    EXPECT_EQ(h.port.result()->origin, "root");
  }
  {
    Harness h(inverter(skill("A")));
    h.engine->start();
    h.fail("root/0");
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  }
}

TEST(EngineInverter, InvertedMonitorWaitsForTheMonitorToFire) {
  // "Wait until the force exceeds a limit": a common use of a monitor under an Inverter.
  Harness h(sequence({inverter(monitor("ForceMonitor")), skill("Next")}));
  h.engine->start();
  h.fail("root/0/0", "FORCE_LIMIT");
  EXPECT_EQ(h.port.starts().back(), "root/1");
}

TEST(EngineForceSuccess, SucceedsEitherWay) {
  for (const bool child_ok : {true, false}) {
    Harness h(force_success(skill("A")));
    h.engine->start();
    child_ok ? h.succeed("root/0") : h.fail("root/0");
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded) << child_ok;
  }
}

TEST(EngineRetry, RestartsAfterFailureUpToMaxAttempts) {
  Harness h(retry(3, skill("A")));
  h.engine->start();
  h.fail("root/0");
  EXPECT_EQ(h.act("root/0"), 2U);
  EXPECT_EQ(h.state("root/0"), NodeState::kRunning);
  h.fail("root/0");
  EXPECT_EQ(h.act("root/0"), 3U);
  h.fail("root/0", "THIRD");
  EXPECT_EQ(h.port.starts().size(), 3U);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, "THIRD");
  EXPECT_NE(h.port.result()->message.find("3 attempt"), std::string::npos);
}

TEST(EngineRetry, SucceedsOnSecondAttempt) {
  Harness h(retry(3, skill("A")));
  h.engine->start();
  h.fail("root/0");
  h.succeed("root/0");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_EQ(h.port.starts().size(), 2U);
}

TEST(EngineRetry, OneAttemptMeansNoRetry) {
  Harness h(retry(1, skill("A")));
  h.engine->start();
  h.fail("root/0");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.starts().size(), 1U);
}

TEST(EngineRetry, LateEventFromEarlierAttemptIsStale) {
  Harness h(retry(2, skill("A")));
  h.engine->start();
  h.fail("root/0");
  LeafEvent late;
  late.kind = LeafEventKind::kSuccess;
  late.activation = 1;
  const auto r = h.engine->on_leaf_event("root/0", late);
  EXPECT_EQ(r.status, EventStatus::kStaleActivation);
  EXPECT_EQ(h.state("root/0"), NodeState::kRunning);
  EXPECT_FALSE(h.port.result());
}

TEST(EngineRetry, RestartResetsDescendantsToIdle) {
  Harness h(retry(2, sequence({skill("A"), skill("B")})));
  h.engine->start();
  h.succeed("root/0/0");
  h.fail("root/0/1");
  // The sequence restarted: A runs again (activation 2), B is back to IDLE.
  EXPECT_EQ(h.state("root/0/0"), NodeState::kRunning);
  EXPECT_EQ(h.act("root/0/0"), 2U);
  EXPECT_EQ(h.state("root/0/1"), NodeState::kIdle);
  EXPECT_EQ(h.act("root/0/1"), 1U);
  h.succeed("root/0/0");
  EXPECT_EQ(h.act("root/0/1"), 2U);
  h.succeed("root/0/1");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineRepeat, RestartsAfterSuccessCountTimes) {
  Harness h(repeat(3, skill("A")));
  h.engine->start();
  h.succeed("root/0");
  h.succeed("root/0");
  EXPECT_FALSE(h.port.result());
  h.succeed("root/0");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  EXPECT_EQ(h.port.starts().size(), 3U);
}

TEST(EngineRepeat, FailureStopsRepeating) {
  Harness h(repeat(5, skill("A")));
  h.engine->start();
  h.succeed("root/0");
  h.fail("root/0", "OOPS");
  EXPECT_EQ(h.port.result()->code, "OOPS");
  EXPECT_NE(h.port.result()->message.find("repetition 2"), std::string::npos);
  EXPECT_EQ(h.port.starts().size(), 2U);
}

TEST(EngineTimeout, ChildFinishingInTimeCancelsTheDeadline) {
  Harness h(timeout(10.0, skill("A")));
  h.engine->start();
  EXPECT_EQ(h.port.timers().size(), 1U);
  h.advance(5.0);
  h.succeed("root/0");
  EXPECT_TRUE(h.port.timers().empty());
  EXPECT_EQ(h.engine->pending_timers(), 0U);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineTimeout, DeadlineShutsChildDownThenFailsWithTimeout) {
  Harness h(timeout(10.0, skill("A")));
  h.engine->start();
  h.advance(9.9);
  EXPECT_TRUE(h.port.shutdowns().empty());
  h.advance(0.2);
  EXPECT_EQ(h.port.shutdowns(), std::vector<std::string>{"root/0"});
  EXPECT_EQ(h.state("root/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root"), NodeState::kRunning);  // waits for the child to stop
  EXPECT_FALSE(h.port.result());
  h.stopped("root/0");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kFailed);
  EXPECT_EQ(h.port.result()->code, codes::kTimeout);
  EXPECT_EQ(h.port.result()->origin, "root");
}

TEST(EngineTimeout, ChildFailureBeforeDeadlinePropagates) {
  Harness h(timeout(10.0, skill("A")));
  h.engine->start();
  h.fail("root/0", "EARLY");
  EXPECT_EQ(h.port.result()->code, "EARLY");
  EXPECT_TRUE(h.port.timers().empty());
}

TEST(EngineTimeout, SuccessRacingTheDeadlineStillTimesOut) {
  Harness h(timeout(1.0, skill("A")));
  h.engine->start();
  h.advance(1.0);
  ASSERT_EQ(h.state("root/0"), NodeState::kStopping);
  EXPECT_EQ(h.succeed("root/0").status, EventStatus::kAccepted);
  EXPECT_EQ(h.status("root/0").code, codes::kFinishedWhileStopping);
  EXPECT_EQ(h.port.result()->code, codes::kTimeout);
}

TEST(EngineTimeout, StaleDeadlineTimerIsRejected) {
  Harness h(timeout(1.0, skill("A")));
  h.engine->start();
  const TimerId id = h.port.timers().begin()->first;
  h.succeed("root/0");
  EXPECT_EQ(h.engine->on_timer(id).status, EventStatus::kUnknownTimer);
  EXPECT_EQ(h.engine->on_timer(12345).status, EventStatus::kUnknownTimer);
}

TEST(EngineOperatorDecision, RunsTheChosenBranch) {
  Harness h(decision("Which screw?", {{"M12", skill("ScrewM12")}, {"M16", skill("ScrewM16")}}));
  h.engine->start();
  EXPECT_EQ(h.port.log().back(), "ask root");
  EXPECT_TRUE(h.port.starts().empty());
  EXPECT_EQ(h.decide("root", 1).status, EventStatus::kAccepted);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/1"});
  EXPECT_EQ(h.state("root/0"), NodeState::kIdle);
  EXPECT_NE(h.status("root").message.find("M16"), std::string::npos);
  h.succeed("root/1");
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineOperatorDecision, BranchFailureFails) {
  Harness h(decision("?", {{"a", skill("A")}, {"b", skill("B")}}));
  h.engine->start();
  h.decide("root", 0);
  h.fail("root/0", "NOPE");
  EXPECT_EQ(h.port.result()->code, "NOPE");
}

TEST(EngineOperatorDecision, RejectsOutOfRangeAndSecondAnswers) {
  Harness h(decision("?", {{"a", skill("A")}, {"b", skill("B")}}));
  h.engine->start();
  EXPECT_EQ(h.decide("root", 2).status, EventStatus::kInvalidArgument);
  EXPECT_EQ(h.decide("root", 0).status, EventStatus::kAccepted);
  EXPECT_EQ(h.decide("root", 1).status, EventStatus::kNotActive);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/0"});
}

TEST(EngineOperatorDecision, ShutdownWithdrawsTheQuestion) {
  Harness h(parallel(1, 1, {decision("?", {{"a", skill("A")}}), monitor("M")}));
  h.engine->start();
  h.fail("root/1", "FIRED");
  EXPECT_EQ(h.port.count("withdraw root/0"), 1U);
  EXPECT_EQ(h.state("root/0"), NodeState::kStopped);
  EXPECT_EQ(h.port.result()->code, "FIRED");
  EXPECT_EQ(h.decide("root/0", 0).status, EventStatus::kNotActive);
}

// --- Input validation -------------------------------------------------------------------------

TEST(EngineInput, RejectsUnknownNodeWrongKindAndBadActivation) {
  Harness h(sequence({skill("A"), condition("C"), decision("?", {{"x", skill("X")}})}));
  h.engine->start();
  LeafEvent e;
  e.kind = LeafEventKind::kSuccess;
  e.activation = 1;
  EXPECT_EQ(h.engine->on_leaf_event("root/9", e).status, EventStatus::kUnknownNode);
  EXPECT_EQ(h.engine->on_leaf_event("root", e).status, EventStatus::kWrongKind);
  EXPECT_EQ(h.engine->on_leaf_event("root/1", e).status, EventStatus::kWrongKind);
  EXPECT_EQ(h.engine->on_condition_result("root/0", 1, true).status, EventStatus::kWrongKind);
  EXPECT_EQ(h.engine->on_operator_decision("root/0", 1, 0).status, EventStatus::kWrongKind);
  e.activation = 2;
  EXPECT_EQ(h.engine->on_leaf_event("root/0", e).status, EventStatus::kInvalidActivation);
  e.activation = 0;
  EXPECT_EQ(h.engine->on_leaf_event("root/0", e).status, EventStatus::kInvalidActivation);
  // Not yet started: activation 0, so any activation is invalid.
  EXPECT_EQ(h.engine->on_condition_result("root/1", 1, true).status, EventStatus::kInvalidActivation);
  EXPECT_EQ(h.state("root/0"), NodeState::kRunning);
  EXPECT_EQ(h.state("root"), NodeState::kRunning);
}

TEST(EngineInput, DuplicateAndLateEventsAreRejectedAndChangeNothing) {
  Harness h(sequence({skill("A"), skill("B")}));
  h.engine->start();
  EXPECT_EQ(h.succeed("root/0").status, EventStatus::kAccepted);
  const auto log_size = h.port.log().size();
  const auto r1 = h.succeed("root/0");
  EXPECT_EQ(r1.status, EventStatus::kNotActive);
  EXPECT_NE(r1.reason.find("duplicate or late"), std::string::npos);
  EXPECT_EQ(h.fail("root/0").status, EventStatus::kNotActive);
  EXPECT_EQ(h.leaf("root/0", LeafEventKind::kProgress).status, EventStatus::kNotActive);
  EXPECT_EQ(h.port.log().size(), log_size);
  EXPECT_EQ(h.state("root/0"), NodeState::kSuccess);
  EXPECT_EQ(h.state("root/1"), NodeState::kRunning);
}

TEST(EngineInput, StoppedWithoutShutdownIsAFailureSoTheTaskGoesOn) {
  Harness h(sequence({skill("A"), skill("B")}));
  h.engine->start();
  const auto r = h.stopped("root/0");
  EXPECT_TRUE(r.acted_on()) << r.reason;
  EXPECT_EQ(h.state("root/0"), NodeState::kFailure);
  EXPECT_EQ(h.state("root"), NodeState::kFailure);
  EXPECT_EQ(h.state("root/1"), NodeState::kIdle) << "the sequence must not go on after the stopped leaf";
  EXPECT_EQ(h.port.result()->code, codes::kStoppedByExecutor);
  EXPECT_EQ(h.port.result()->origin, "root/0");
}

TEST(EngineInput, EventsBeforeStartAreRejected) {
  Harness h(skill("A"));
  LeafEvent e;
  e.kind = LeafEventKind::kSuccess;
  e.activation = 1;
  EXPECT_EQ(h.engine->on_leaf_event("root", e).status, EventStatus::kInvalidActivation);
  EXPECT_TRUE(h.port.log().empty());
}

TEST(EngineInput, StartTwiceAndAfterFinishIsWrongPhase) {
  Harness h(skill("A"));
  EXPECT_EQ(h.engine->start().status, EventStatus::kAccepted);
  EXPECT_EQ(h.engine->start().status, EventStatus::kWrongPhase);
  h.succeed("root");
  EXPECT_EQ(h.engine->start().status, EventStatus::kWrongPhase);
  EXPECT_EQ(h.engine->cancel("late").status, EventStatus::kWrongPhase);
  EXPECT_EQ(h.engine->pause().status, EventStatus::kWrongPhase);
  EXPECT_EQ(h.port.finished_count(), 1);
}

class ReentrantPort : public testing::FakePort {
 public:
  Engine* engine = nullptr;
  EventResult inner;
  void start_leaf(const NodeSpec& node, Activation activation) override {
    FakePort::start_leaf(node, activation);
    LeafEvent e;
    e.kind = LeafEventKind::kSuccess;
    e.activation = activation;
    inner = engine->on_leaf_event(node.id, e);
  }
};

TEST(EngineInput, PortCallingBackIsRefused) {
  ReentrantPort port;
  Engine engine(build::build(skill("A")), port);
  port.engine = &engine;
  engine.start();
  EXPECT_EQ(port.inner.status, EventStatus::kReentrant);
  EXPECT_EQ(engine.status(0).state, NodeState::kRunning);
  // Delivered again from outside, it is accepted.
  LeafEvent e;
  e.kind = LeafEventKind::kSuccess;
  e.activation = 1;
  EXPECT_EQ(engine.on_leaf_event("root", e).status, EventStatus::kAccepted);
}

// --- Spec checks ----------------------------------------------------------------------------

TEST(EngineSpec, RejectsMalformedTrees) {
  testing::FakePort port;
  auto expect_error = [&](const build::Node& root, const std::string& fragment) {
    try {
      Engine engine(build::build(root), port);
      ADD_FAILURE() << "expected SpecError containing " << fragment;
    } catch (const SpecError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error(parallel(2, 1, {skill("A"), monitor("M"), monitor("N")}), "success threshold 2 infeasible");
  expect_error(parallel(1, 4, {skill("A"), monitor("M"), monitor("N")}), "failure threshold 4 infeasible");
  expect_error(parallel(0, 1, {skill("A")}), "success threshold 0");
  expect_error(parallel(1, 1, {monitor("M")}), "success threshold 1 infeasible");
  expect_error(sequence({}), "at least one child");
  expect_error(retry(0, skill("A")), "count must be at least 1");
  expect_error(timeout(0.0, skill("A")), "duration must be positive");
  expect_error(timeout(1e300, skill("A")), "at most 1e7 s");
  expect_error(skill(""), "names no skill");
  auto bad_stop = skill("A");
  bad_stop.stop_timeout_s = 0;
  expect_error(bad_stop, "stop timeout");
  auto decision_node = decision("?", {{"a", skill("A")}});
  decision_node.options.push_back("b");
  expect_error(decision_node, "2 options but 1 children");

  TreeSpec cyclic = build::build(sequence({skill("A")}));
  cyclic.nodes[1].kind = NodeKind::kSequence;
  cyclic.nodes[1].children = {0};
  EXPECT_THROW(Engine(cyclic, port), SpecError);
  TreeSpec dup = build::build(sequence({skill("A"), skill("B")}));
  dup.nodes[2].id = "root/0";
  EXPECT_THROW(Engine(dup, port), SpecError);
  TreeSpec out_of_range = build::build(sequence({skill("A")}));
  out_of_range.nodes[0].children = {7};
  EXPECT_THROW(Engine(out_of_range, port), SpecError);
  TreeSpec orphan = build::build(sequence({skill("A")}));
  orphan.nodes.push_back(orphan.nodes[1]);
  orphan.nodes.back().id = "lost";
  EXPECT_THROW(Engine(orphan, port), SpecError);
  EXPECT_THROW(Engine(TreeSpec{}, port), SpecError);
  TreeSpec deep;
  for (std::size_t i = 0; i <= kMaxTreeDepth; ++i) {
    NodeSpec n;
    n.kind = NodeKind::kInverter;
    n.id = "n" + std::to_string(i);
    n.children = {i + 1};
    deep.nodes.push_back(n);
  }
  deep.nodes.back().kind = NodeKind::kSkill;
  deep.nodes.back().leaf = "A";
  deep.nodes.back().children.clear();
  EXPECT_THROW(Engine(deep, port), SpecError);
  deep.nodes.erase(deep.nodes.begin());
  for (auto& n : deep.nodes) {
    for (auto& c : n.children) {
      --c;
    }
  }
  EXPECT_NO_THROW(Engine(deep, port));
}

TEST(EngineSpec, CanSucceedFollowsTypedCounting) {
  const TreeSpec spec = build::build(sequence({
      monitor("M"),                                          // root/0: no
      inverter(monitor("M")),                                // root/1: yes
      sequence({skill("A"), monitor("M")}),                  // root/2: no
      fallback({monitor("M"), skill("A")}),                  // root/3: yes
      parallel(1, 1, {skill("A"), monitor("M")}),            // root/4: yes
      timeout(1.0, monitor("M")),                            // root/5: no
      decision("?", {{"a", monitor("M")}, {"b", condition("C")}}),  // root/6: yes
      retry(2, monitor("M")),                                // root/7: no
      force_success(monitor("M")),                           // root/8: yes
  }));
  const auto can = compute_can_succeed(spec);
  auto at = [&](const std::string& id) {
    for (NodeIndex i = 0; i < spec.nodes.size(); ++i) {
      if (spec.nodes[i].id == id) {
        return static_cast<bool>(can[i]);
      }
    }
    ADD_FAILURE() << id;
    return false;
  };
  EXPECT_FALSE(at("root"));
  EXPECT_FALSE(at("root/0"));
  EXPECT_TRUE(at("root/1"));
  EXPECT_FALSE(at("root/2"));
  EXPECT_TRUE(at("root/3"));
  EXPECT_TRUE(at("root/4"));
  EXPECT_FALSE(at("root/5"));
  EXPECT_TRUE(at("root/6"));
  EXPECT_FALSE(at("root/7"));
  EXPECT_TRUE(at("root/8"));
}

TEST(EngineSpec, NodeKindNamesRoundTrip) {
  for (const auto kind : {NodeKind::kSequence, NodeKind::kFallback, NodeKind::kParallel, NodeKind::kSkill,
                          NodeKind::kMonitor, NodeKind::kCondition, NodeKind::kInverter, NodeKind::kRetry,
                          NodeKind::kRepeat, NodeKind::kTimeout, NodeKind::kForceSuccess,
                          NodeKind::kOperatorDecision}) {
    EXPECT_EQ(node_kind_from_string(to_string(kind)), kind);
  }
  EXPECT_FALSE(node_kind_from_string("Root"));
}

}  // namespace
}  // namespace rigger::bt
