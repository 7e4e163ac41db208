// The Skill base: states, synchronous and asynchronous transitions, guarded callbacks, state-scoped
// timers and operations, and the shutdown/failure paths through each state's safe stop.
#include <gtest/gtest.h>

#include "rigger/skill_sdk/testing/run_harness.hpp"
#include "rigger/skill_sdk/skill.hpp"

namespace rigger::skill_sdk {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

// wait (1 s timer) → act (waits for the test's `act_done`) → check (synchronous) → SUCCESS.
// Safe stops: wait: nothing; act: completes when the test calls `stop_done`; check: nothing.
class ToySkill final : public Skill {
 public:
  static inline std::function<void(bool)> act_done;     // completes the act state's "primitive"
  static inline SafeStopDone stop_done;                 // completes the act state's safe stop
  static inline std::function<void()> stale_act_done;   // an act callback kept after act was left
  static inline bool throw_in_check = false;
  static inline bool fail_in_check = false;
  static inline std::vector<std::string> entered;

  ToySkill() {
    add_state({"wait", [this] {
                 entered.push_back("wait");
                 after(1s, [this] { transition("act"); });
               },
               nothing_to_stop});
    add_state({"act", [this] {
                 entered.push_back("act");
                 act_done = guard([this](bool ok) {
                   if (ok) transition("check");
                   else fail("ACT_FAILED", "the act failed");
                 });
                 stale_act_done = guard([this] { fail("STALE", "a stale callback ran"); });
               },
               [](SafeStopDone done) { stop_done = std::move(done); }});
    add_state({"check", [this] {
                 entered.push_back("check");
                 if (throw_in_check) throw std::runtime_error("boom");
                 if (fail_in_check) fail("CHECK_FAILED", "not ok");
                 else succeed("checked");
               },
               nothing_to_stop});
  }
  static SkillType type() {
    skill::SkillDescription d;
    d.name = "Toy";
    return {d, [] { return std::make_unique<ToySkill>(); }};
  }
};

class SkillFsmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ToySkill::act_done = nullptr;
    ToySkill::stop_done = nullptr;
    ToySkill::stale_act_done = nullptr;
    ToySkill::throw_in_check = false;
    ToySkill::fail_in_check = false;
    ToySkill::entered.clear();
  }
  SkillType type_ = ToySkill::type();
  RunHarness h_{type_, nlohmann::json::object()};
};

TEST_F(SkillFsmTest, RunsThroughItsStatesToSuccess) {
  h_.run->start();
  EXPECT_EQ(h_.run->skill()->state(), "wait");
  h_.timers.advance(999ms);
  EXPECT_EQ(h_.run->skill()->state(), "wait");
  h_.timers.advance(1ms);
  EXPECT_EQ(h_.run->skill()->state(), "act");
  ToySkill::act_done(true);
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(h_.result->message, "checked");
  EXPECT_EQ(ToySkill::entered, (std::vector<std::string>{"wait", "act", "check"}));
  EXPECT_EQ(h_.results, 1);
}

TEST_F(SkillFsmTest, CallbacksOfALeftStateAreDropped) {
  h_.run->start();
  h_.timers.advance(1s);
  auto stale = ToySkill::stale_act_done;
  ToySkill::act_done(true);  // leaves act
  ASSERT_TRUE(h_.result);
  stale();                   // must not turn the success into a failure
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(h_.results, 1);
}

TEST_F(SkillFsmTest, FailureRunsTheSafeStopBeforeReporting) {
  h_.run->start();
  h_.timers.advance(1s);
  ToySkill::act_done(false);
  EXPECT_FALSE(h_.result) << "reported before the safe stop completed";
  ASSERT_TRUE(ToySkill::stop_done);
  ToySkill::stop_done(true, "at rest");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kFailure);
  EXPECT_EQ(h_.result->code, "ACT_FAILED");
}

TEST_F(SkillFsmTest, ShutdownInAStateWithNothingToStopIsStoppedAtOnceAndCancelsItsTimer) {
  h_.run->start();
  EXPECT_EQ(h_.timers.pending(), 1u);
  h_.run->shutdown("test");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kStopped);
  EXPECT_EQ(h_.timers.pending(), 0u);
  h_.timers.advance(5s);
  EXPECT_EQ(ToySkill::entered, std::vector<std::string>{"wait"});
}

TEST_F(SkillFsmTest, ShutdownIsStoppedOnlyWhenTheSafeStopIsReached) {
  h_.run->start();
  h_.timers.advance(1s);
  h_.run->shutdown("test");
  EXPECT_FALSE(h_.result);
  h_.run->shutdown("again");  // ignored: a safe stop is under way
  ToySkill::act_done(true);   // the primitive's late completion must not move the FSM on
  EXPECT_FALSE(h_.result);
  ToySkill::stop_done(true, "at rest");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kStopped);
  EXPECT_NE(h_.result->message.find("act"), std::string::npos);
  EXPECT_EQ(h_.results, 1);
}

TEST_F(SkillFsmTest, AFailedSafeStopIsAFailureNotStopped) {
  h_.run->start();
  h_.timers.advance(1s);
  h_.run->shutdown("test");
  ToySkill::stop_done(false, "the arm does not stop");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kFailure);
  EXPECT_EQ(h_.result->code, "SAFE_STOP_FAILED");
}

TEST_F(SkillFsmTest, AStateThatThrowsFailsWithSkillError) {
  ToySkill::throw_in_check = true;
  h_.run->start();
  h_.timers.advance(1s);
  ToySkill::act_done(true);
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->code, "SKILL_ERROR");
  EXPECT_NE(h_.result->message.find("boom"), std::string::npos);
}

TEST_F(SkillFsmTest, ShutdownAfterTheEndChangesNothing) {
  ToySkill::fail_in_check = true;
  h_.run->start();
  h_.timers.advance(1s);
  ToySkill::act_done(true);
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->code, "CHECK_FAILED");
  h_.run->shutdown("late");
  EXPECT_EQ(h_.results, 1);
}

class BadSkill final : public Skill {
 public:
  explicit BadSkill(int variant) {
    if (variant == 0) add_state({"a", [] {}, nullptr});
    if (variant == 1) {
      add_state({"a", [] {}, nothing_to_stop});
      add_state({"a", [] {}, nothing_to_stop});
    }
    if (variant == 2) add_state({"a", nullptr, nothing_to_stop});
  }
};

TEST(SkillStates, EveryStateNeedsAnEnterActionAndASafeStop) {
  EXPECT_THROW(BadSkill(0), std::logic_error);
  EXPECT_THROW(BadSkill(1), std::logic_error);
  EXPECT_THROW(BadSkill(2), std::logic_error);
}

}  // namespace
}  // namespace rigger::skill_sdk

namespace rigger::skill_sdk {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

// move (a 5 s timeout; ends when the test calls `move_done`; held on pause) → SUCCESS.
class HoldingSkill final : public Skill {
 public:
  static inline std::function<void()> move_done;
  static inline SafeStopDone hold_done;  // completes the hold of a pause
  static inline int entered = 0, safe_stops = 0;

  HoldingSkill() {
    add_state({"move",
               [this] {
                 ++entered;
                 after(5s, [this] { fail("TIMEOUT", "not there in 5 s"); });
                 move_done = guard([this] { succeed("there"); });
               },
               [](SafeStopDone done) {
                 ++safe_stops;
                 done(true, "stopped");
               },
               [](SafeStopDone done) { hold_done = std::move(done); }});
  }
  static SkillType type() {
    skill::SkillDescription d;
    d.name = "Holding";
    d.pausable = true;
    return {d, [] { return std::make_unique<HoldingSkill>(); }};
  }
};

class SkillPauseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    HoldingSkill::move_done = nullptr;
    HoldingSkill::hold_done = nullptr;
    HoldingSkill::entered = 0;
    HoldingSkill::safe_stops = 0;
  }
  SkillType type_ = HoldingSkill::type();
  RunHarness h_{type_, nlohmann::json::object()};
};

TEST_F(SkillPauseTest, APauseHoldsTheStateItsTimeoutDoesNotRunOutAndResumeEntersItAgain) {
  h_.run->start();
  ASSERT_EQ(HoldingSkill::entered, 1);
  auto late = HoldingSkill::move_done;
  EXPECT_TRUE(h_.run->pause(true));
  EXPECT_FALSE(h_.run->pause(true)) << "paused already";
  ASSERT_TRUE(HoldingSkill::hold_done) << "the hold was not run";
  EXPECT_TRUE(h_.run->skill()->paused());
  late();  // the motion's late event: the state was left, it drives nothing
  h_.timers.advance(60s);
  EXPECT_FALSE(h_.result) << "a timeout ran out while paused: " << h_.result->code;
  HoldingSkill::hold_done(true, "at rest");
  EXPECT_FALSE(h_.result);
  EXPECT_TRUE(h_.run->pause(false));
  EXPECT_FALSE(h_.run->pause(false)) << "not paused any more";
  EXPECT_EQ(HoldingSkill::entered, 2);
  h_.timers.advance(4s);
  EXPECT_FALSE(h_.result) << "the timeout counts afresh from the resume";
  h_.timers.advance(2s);
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->code, "TIMEOUT");
}

TEST_F(SkillPauseTest, ResumedItSucceeds) {
  h_.run->start();
  EXPECT_TRUE(h_.run->pause(true));
  HoldingSkill::hold_done(true, "at rest");
  EXPECT_TRUE(h_.run->pause(false));
  HoldingSkill::move_done();
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(HoldingSkill::safe_stops, 0);
}

TEST_F(SkillPauseTest, AHoldThatFailsEndsTheRunThroughItsSafeStop) {
  h_.run->start();
  EXPECT_TRUE(h_.run->pause(true));
  HoldingSkill::hold_done(false, "the arm did not stop");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kFailure);
  EXPECT_EQ(h_.result->code, "HOLD_FAILED");
  EXPECT_NE(h_.result->message.find("the arm did not stop"), std::string::npos) << h_.result->message;
  EXPECT_EQ(HoldingSkill::safe_stops, 1);
}

TEST_F(SkillPauseTest, AShutdownWhilePausedRunsTheSafeStop) {
  h_.run->start();
  EXPECT_TRUE(h_.run->pause(true));
  h_.run->shutdown("canceled");
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kStopped);
  EXPECT_EQ(HoldingSkill::safe_stops, 1);
  EXPECT_FALSE(h_.run->pause(false)) << "the run has ended";
}

// A state without a hold (it commands no motion) runs on while paused; the state it hands over to is
// entered only on resume.
TEST_F(SkillFsmTest, AStateWithoutAHoldRunsOnAndTheNextWaitsForTheResume) {
  h_.run->start();
  EXPECT_TRUE(h_.run->pause(true));
  h_.timers.advance(2s);  // wait's 1 s timer fires: it asks for act
  EXPECT_EQ(ToySkill::entered, (std::vector<std::string>{"wait"}));
  EXPECT_FALSE(h_.result);
  EXPECT_TRUE(h_.run->pause(false));
  EXPECT_EQ(ToySkill::entered, (std::vector<std::string>{"wait", "act"}));
  ToySkill::act_done(true);
  ASSERT_TRUE(h_.result);
  EXPECT_EQ(h_.result->kind, SkillResult::Kind::kSuccess);
}

}  // namespace
}  // namespace rigger::skill_sdk
