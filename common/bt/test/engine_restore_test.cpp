// Engine::start(const Restoration&): a task resumed from its journal after a controller crash.
#include <gtest/gtest.h>

#include "fake_port.hpp"

namespace rigger::bt {
namespace {

using namespace build;
using testing::Harness;

Restoration fresh(const Harness& h) {
  return Restoration{std::vector<RestoredNode>(h.engine->spec().nodes.size())};
}

void set(Restoration& r, const Harness& h, const std::string& id, Restored how, std::string code = "") {
  auto& n = r.nodes[h.index(id)];
  n.how = how;
  n.code = std::move(code);
  n.activations = 1;
}

TEST(EngineRestore, SequenceContinuesAfterItsDoneChildren) {
  Harness h(sequence({skill("A"), skill("B"), skill("C")}));
  Restoration r = fresh(h);
  set(r, h, "root/0", Restored::kSucceeded);
  r.nodes[h.index("root/1")].activations = 1;  // B was running: it starts again as activation 2
  ASSERT_TRUE(h.engine->start(r).acted_on());
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/1"});
  EXPECT_EQ(h.state("root/0"), NodeState::kSuccess);
  EXPECT_EQ(h.act("root/1"), 2U);
  h.succeed("root/1");
  h.succeed("root/2");
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/1", "root/2"}));
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineRestore, ADoneSubtreeRunsNothingBelowIt) {
  Harness h(sequence({sequence({skill("A"), skill("B")}), skill("C")}));
  Restoration r = fresh(h);
  set(r, h, "root/0", Restored::kSucceeded);
  h.engine->start(r);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/1"});
  EXPECT_EQ(h.state("root/0/0"), NodeState::kIdle);
}

TEST(EngineRestore, AllChildrenDoneFinishesTheTaskWithoutAnyStart) {
  Harness h(sequence({skill("A"), skill("B")}));
  Restoration r = fresh(h);
  set(r, h, "root/0", Restored::kSucceeded);
  set(r, h, "root/1", Restored::kSucceeded);
  h.engine->start(r);
  EXPECT_TRUE(h.port.starts().empty());
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineRestore, FallbackSkipsItsFailedAlternativesAndADoneFallbackIsDone) {
  Harness h(sequence({fallback({skill("A"), skill("B"), skill("C")}), fallback({skill("D"), skill("E")})}));
  Restoration r = fresh(h);
  set(r, h, "root/0/0", Restored::kFailed, "A_BROKE");  // A failed, B was running
  h.engine->start(r);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/0/1"});
  h.fail("root/0/1");
  h.succeed("root/0/2");
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/0/1", "root/0/2", "root/1/0"}));

  Harness done(sequence({fallback({skill("A"), skill("B")}), skill("C")}));
  Restoration rd = fresh(done);
  set(rd, done, "root/0", Restored::kSucceeded);
  done.engine->start(rd);
  EXPECT_EQ(done.port.starts(), std::vector<std::string>{"root/1"});
}

TEST(EngineRestore, RetryKeepsItsFailedRuns) {
  Harness h(retry(3, skill("A")));
  Restoration r = fresh(h);
  r.nodes[h.index("root")].cursor = 2;  // two runs failed; the third was running
  r.nodes[h.index("root/0")].activations = 3;
  h.engine->start(r);
  EXPECT_EQ(h.act("root/0"), 4U);
  h.fail("root/0", "THIRD");
  EXPECT_EQ(h.port.starts().size(), 1U);  // no fourth run: max_attempts counts the runs before the crash
  EXPECT_EQ(h.port.result()->code, "THIRD");
}

TEST(EngineRestore, RepeatKeepsItsSuccesses) {
  Harness h(repeat(3, skill("A")));
  Restoration r = fresh(h);
  r.nodes[h.index("root")].cursor = 2;
  h.engine->start(r);
  h.succeed("root/0");
  EXPECT_EQ(h.port.starts().size(), 1U);
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineRestore, ParallelCountsItsFinishedChildrenAndStartsOnlyTheOthers) {
  Harness h(parallel(2, 1, {skill("A"), skill("B"), monitor("M")}));
  Restoration r = fresh(h);
  set(r, h, "root/0", Restored::kSucceeded);
  h.engine->start(r);
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/1", "root/2"}));
  h.succeed("root/1");  // the second success: M = 2 reached, the monitor is shut down
  EXPECT_EQ(h.port.shutdowns(), std::vector<std::string>{"root/2"});
  h.stop_all_stopping();
  EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
}

TEST(EngineRestore, AParallelDecidedByItsRestoredChildrenStartsNothing) {
  // The monitor had fired and the skill was being stopped when the controller died.
  Harness h(sequence({parallel(1, 1, {skill("A"), monitor("M")}), skill("B")}));
  Restoration r = fresh(h);
  set(r, h, "root/0/0", Restored::kStopped);
  set(r, h, "root/0/1", Restored::kFailed, "YANK_DETECTED");
  h.engine->start(r);
  EXPECT_TRUE(h.port.starts().empty());
  EXPECT_TRUE(h.port.shutdowns().empty());
  EXPECT_EQ(h.port.result()->code, "YANK_DETECTED");
}

TEST(EngineRestore, DecoratorsPassRestoredResultsOn) {
  Harness h(sequence({inverter(skill("A")), force_success(skill("B")), timeout(5, skill("C"))}));
  Restoration r = fresh(h);
  set(r, h, "root/0/0", Restored::kFailed, "GONE");  // inverted: success
  set(r, h, "root/1/0", Restored::kFailed, "ALSO");  // forced: success
  h.engine->start(r);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/2/0"});
  EXPECT_EQ(h.port.timers().size(), 1U);  // the Timeout's deadline counts afresh from the resume
}

TEST(EngineRestore, AnOperatorsChoiceStandsAndNobodyIsAskedAgain) {
  Harness h(decision("which?", {{"left", skill("L")}, {"right", skill("R")}}));
  Restoration r = fresh(h);
  r.nodes[h.index("root")].chosen = 1;
  h.engine->start(r);
  EXPECT_EQ(h.port.count("ask root"), 0U);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/1"});

  Harness unanswered(decision("which?", {{"left", skill("L")}, {"right", skill("R")}}));
  unanswered.engine->start(fresh(unanswered));
  EXPECT_EQ(unanswered.port.count("ask root"), 1U);
}

TEST(EngineRestore, ARetryRestartAfterTheResumeRunsNormally) {
  Harness h(sequence({skill("A"), retry(2, sequence({skill("B"), skill("C")}))}));
  Restoration r = fresh(h);
  set(r, h, "root/0", Restored::kSucceeded);
  set(r, h, "root/1/0/0", Restored::kSucceeded);  // B done, C was running
  h.engine->start(r);
  EXPECT_EQ(h.port.starts(), std::vector<std::string>{"root/1/0/1"});
  h.fail("root/1/0/1");  // the retry's second run starts from B: restored state is used once only
  EXPECT_EQ(h.port.starts(), (std::vector<std::string>{"root/1/0/1", "root/1/0/0"}));
}

TEST(EngineRestore, ARestorationOfAnotherSizeIsRefused) {
  Harness h(sequence({skill("A")}));
  EXPECT_EQ(h.engine->start(Restoration{}).status, EventStatus::kInvalidArgument);
  EXPECT_FALSE(h.engine->started());
}

}  // namespace
}  // namespace rigger::bt
