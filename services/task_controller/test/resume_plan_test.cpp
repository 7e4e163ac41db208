// plan_resume: journal timeline → restored tree. The timelines come from a real Engine run on a port that
// writes NODE rows as Task::node_changed does, stopped where the controller "died"; the plan is then run
// on a fresh Engine (the restarted controller) to see what starts.
#include <gtest/gtest.h>

#include "resume_plan.hpp"
#include "rigger/bt/engine.hpp"
#include "rigger/bt/tree_builder.hpp"
#include "unit_test_util.hpp"

namespace rigger::task_controller {
namespace {

using namespace bt::build;
using bt::NodeState;

using testing::JournalingPort;

/// The killed controller's run (`before`) and the restarted one's (`after`) of the same tree.
struct Crash {
  explicit Crash(const Node& root) : spec(build(root)), before(spec, first), after_engine(spec, second) {
    before.start();
  }
  bt::LeafEvent event(const std::string& id, bt::LeafEventKind kind, const std::string& code = "") {
    bt::LeafEvent e;
    e.kind = kind;
    e.activation = before.status(*before.find(id)).activation;
    e.code = code;
    return e;
  }
  void succeed(const std::string& id) { before.on_leaf_event(id, event(id, bt::LeafEventKind::kSuccess)); }
  void fail(const std::string& id, const std::string& code = "BROKE") {
    before.on_leaf_event(id, event(id, bt::LeafEventKind::kFailure, code));
  }
  ResumePlan plan() { return plan_resume(spec, first.rows); }
  ResumePlan resume() {
    ResumePlan p = plan();
    EXPECT_EQ(p.error, "");
    EXPECT_TRUE(after_engine.start(p.restoration).acted_on());
    return p;
  }

  bt::TreeSpec spec;
  JournalingPort first, second;
  bt::Engine before;
  bt::Engine after_engine;
};

bt::TreeSpec with_restartable(bt::TreeSpec spec, const std::string& id) {
  for (auto& n : spec.nodes)
    if (n.id == id) n.restartable = true;
  return spec;
}

TEST(ResumePlan, SequenceKilledInItsSecondSkillAsksForItAndRunsTheThird) {
  Crash c(sequence({skill("A"), skill("B"), skill("C")}));
  c.succeed("root/0");  // B runs when the controller dies
  const ResumePlan p = c.resume();
  EXPECT_EQ(p.done, std::vector<std::string>{"root/0"});
  EXPECT_EQ(p.ask, std::vector<std::string>{"root/1"});  // not restartable: the operator decides
  EXPECT_TRUE(p.rerun.empty());
  EXPECT_EQ(p.pending, std::vector<std::string>{"root/2"});
  // The operator chose rerun: B starts again (activation 2: the killed run's events are stale), A never.
  EXPECT_EQ(c.second.starts, std::vector<std::string>{"root/1"});
  EXPECT_EQ(c.after_engine.status(*c.after_engine.find("root/1")).activation, 2U);
  EXPECT_NE(describe_plan(p, c.spec).find("root/0 (A)"), std::string::npos);
}

TEST(ResumePlan, ARestartableSkillRunsAgainWithoutAsking) {
  bt::TreeSpec spec = with_restartable(build(sequence({skill("A"), skill("B")})), "root/0");
  JournalingPort first, second;
  bt::Engine before(spec, first);
  before.start();
  const ResumePlan p = plan_resume(spec, first.rows);
  EXPECT_EQ(p.rerun, std::vector<std::string>{"root/0"});
  EXPECT_TRUE(p.ask.empty());
}

TEST(ResumePlan, SkipTakesTheInterruptedSkillAsDone) {
  Crash c(sequence({skill("A"), skill("B"), skill("C")}));
  c.succeed("root/0");
  ResumePlan p = c.plan();
  skip_interrupted(p, c.spec, "operator:alice");
  EXPECT_TRUE(p.ask.empty());
  c.after_engine.start(p.restoration);
  EXPECT_EQ(c.second.starts, std::vector<std::string>{"root/2"});
  EXPECT_NE(c.after_engine.status(*c.after_engine.find("root/1")).message.find("operator:alice"), std::string::npos);
}

TEST(ResumePlan, RetryKeepsTheAttemptsMadeBeforeTheCrash) {
  Crash c(retry(3, skill("A")));
  c.fail("root/0");
  c.fail("root/0");  // the third and last attempt runs when the controller dies
  const ResumePlan p = c.resume();
  c.after_engine.on_leaf_event("root/0", [&] {
    bt::LeafEvent e;
    e.kind = bt::LeafEventKind::kFailure;
    e.activation = c.after_engine.status(*c.after_engine.find("root/0")).activation;
    return e;
  }());
  ASSERT_TRUE(c.second.result);  // no fourth attempt
  EXPECT_EQ(c.second.starts.size(), 1U);
}

TEST(ResumePlan, FallbackGoesOnAfterItsFailedAlternativeAndTheGuardingConditionIsAskedAgain) {
  Crash c(sequence({condition("Ready"), fallback({skill("A"), skill("B")})}));
  c.before.on_condition_result("root/0", 1, true);
  c.fail("root/1/0");  // B runs
  const ResumePlan p = c.resume();
  EXPECT_TRUE(p.done.empty());
  EXPECT_EQ(p.rerun, std::vector<std::string>{"root/0"});  // it guards the running Fallback
  EXPECT_EQ(p.ask, std::vector<std::string>{"root/1/1"});
  c.after_engine.on_condition_result("root/0", 2, true);
  EXPECT_EQ(c.second.starts, (std::vector<std::string>{"root/0", "root/1/1"}));  // A is not tried again
}

TEST(ResumePlan, ARestartableSkillAMonitorAndAConditionThatRanStartAgainByRule) {
  Crash c(parallel(1, 1, {skill("A"), monitor("M")}));
  c.spec = with_restartable(c.spec, "root/0");
  const ResumePlan p = plan_resume(c.spec, c.first.rows);
  EXPECT_EQ(p.rerun, (std::vector<std::string>{"root/0", "root/1"}));

  Crash d(sequence({condition("Ready"), skill("A")}));  // the world model had not answered yet
  const ResumePlan q = d.resume();
  EXPECT_EQ(q.rerun, std::vector<std::string>{"root/0"});
  EXPECT_EQ(d.second.starts, std::vector<std::string>{"root/0"});  // evaluated again
}

TEST(ResumePlan, AParallelThatHadDecidedIsTakenUpAsDecided) {
  Crash c(sequence({parallel(1, 1, {skill("A"), monitor("M")}), skill("B")}));
  c.fail("root/0/1", "YANK_DETECTED");  // A is STOPPING when the controller dies
  c.resume();
  EXPECT_TRUE(c.second.starts.empty());
  ASSERT_TRUE(c.second.result);
  EXPECT_EQ(c.second.result->code, "YANK_DETECTED");
}

TEST(ResumePlan, ConditionsGuardingTheNextChildAreEvaluatedAgainEarlierOnesAreDone) {
  Crash c(sequence({condition("Early"), skill("A"), condition("Localized"), condition("Clear"), skill("Insert")}));
  c.before.on_condition_result("root/0", 1, true);
  c.succeed("root/1");
  c.before.on_condition_result("root/2", 1, true);
  c.before.on_condition_result("root/3", 1, true);  // Insert runs when the controller dies
  const ResumePlan p = c.resume();
  EXPECT_EQ(p.done, (std::vector<std::string>{"root/0", "root/1"}));
  EXPECT_EQ(p.rerun, (std::vector<std::string>{"root/2", "root/3"}));
  EXPECT_EQ(p.ask, std::vector<std::string>{"root/4"});
  EXPECT_EQ(c.second.starts, std::vector<std::string>{"root/2"});  // evaluated first; Insert only if it holds
  c.after_engine.on_condition_result("root/2", 2, false, "NOT_LOCALIZED");
  ASSERT_TRUE(c.second.result);
  EXPECT_EQ(c.second.result->code, "NOT_LOCALIZED");
  EXPECT_EQ(c.second.starts, std::vector<std::string>{"root/2"}) << "the insertion never started";
}

TEST(ResumePlan, AnOperatorsChoiceIsKept) {
  Crash c(decision("which?", {{"left", skill("L")}, {"right", skill("R")}}));
  c.before.on_operator_decision("root", 1, 1);
  c.resume();
  EXPECT_TRUE(c.second.asked.empty());
  EXPECT_EQ(c.second.starts, std::vector<std::string>{"root/1"});
}

TEST(ResumePlan, ATaskBeingCanceledOrFinishedIsNotResumed) {
  Crash c(sequence({skill("A")}));
  c.before.cancel("stop");
  EXPECT_NE(c.plan().error.find("canceled"), std::string::npos);

  Crash d(sequence({skill("A")}));
  d.succeed("root/0");
  EXPECT_NE(d.plan().error.find("finished"), std::string::npos);
}

TEST(ResumePlan, AJournalThatDoesNotFitTheRecipeIsAnError) {
  const bt::TreeSpec spec = build(sequence({skill("A")}));
  EXPECT_NE(plan_resume(spec, {{0, "t", "root/7", "NODE", "RUNNING", ""}}).error.find("root/7"), std::string::npos);
  EXPECT_NE(plan_resume(spec, {{0, "t", "root", "NODE", "SLEEPING", ""}}).error.find("SLEEPING"), std::string::npos);
}

TEST(ResumePlan, NothingStartedMeansEverythingIsPending) {
  const bt::TreeSpec spec = build(sequence({skill("A"), skill("B")}));
  const ResumePlan p = plan_resume(spec, {});
  EXPECT_EQ(p.error, "");
  EXPECT_EQ(p.pending, (std::vector<std::string>{"root/0", "root/1"}));
}

}  // namespace
}  // namespace rigger::task_controller
