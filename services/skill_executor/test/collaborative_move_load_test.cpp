// CollaborativeMoveLoad's FSM on fakes: crane precondition, engage, the operator's answers and the
// duration, crane and admittance faults during guiding, and shutdown from every state (admittance OFF
// confirmed before STOPPED).
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "rigger/skill/param_check.hpp"
#include "rigger/skill_sdk/states.hpp"
#include "skills/collaborative_move_load.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

AdmittanceSnapshot guiding_state() {
  AdmittanceSnapshot s;
  s.mode = AdmittanceModeRequest::kRobotAndCrane;
  s.reference = AdmittanceReference::kJoystick;
  return s;
}

class CollaborativeMoveLoadTest : public ::testing::Test {
 protected:
  SkillType type_{CollaborativeMoveLoadSkill::describe(),
                  [] { return std::make_unique<CollaborativeMoveLoadSkill>(); }};
  nlohmann::json params_ = nlohmann::json::object();

  /// Runs to `guide`.
  void to_guide(RunHarness& h) {
    h.run->start();
    ASSERT_EQ(h.state(), "check_crane");
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_EQ(h.state(), "crane_external");
    ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
    ASSERT_EQ(h.state(), "engage");
    const AdmittanceRequest* r = h.admittance.pending();
    ASSERT_NE(r, nullptr);
    EXPECT_EQ(r->mode, AdmittanceModeRequest::kRobotAndCrane);
    EXPECT_EQ(r->reference, AdmittanceReference::kJoystick);
    const double k = params_.value("path_stiffness_n_per_m", 200.0);
    EXPECT_EQ(r->stiffness, (std::vector<double>{k, k, k, 0.0, 0.0, 0.0}))
        << "a spring towards the joystick's path on the linear axes only";
    ASSERT_TRUE(h.admittance.complete(OpResult::success()));
    ASSERT_EQ(h.state(), "guide");
  }
};

// The path stiffness is a parameter; 0 is free admittance. Out of range is refused before anything moves.
TEST_F(CollaborativeMoveLoadTest, ThePathStiffnessIsAParameter) {
  params_["path_stiffness_n_per_m"] = 0.0;
  RunHarness h(type_, params_);
  to_guide(h);
  const nlohmann::json too_stiff = {{"path_stiffness_n_per_m", 2500.0}};
  const skill::ParamCheckResult checked = skill::check_params(CollaborativeMoveLoadSkill::describe(), too_stiff);
  ASSERT_EQ(checked.errors.size(), 1u);
  EXPECT_EQ(checked.errors[0].pointer, "/path_stiffness_n_per_m");
}

TEST_F(CollaborativeMoveLoadTest, TheOperatorsDoneEndsItWithAdmittanceOff) {
  RunHarness h(type_, params_);
  to_guide(h);
  EXPECT_EQ(h.crane.watches(), 1u);
  EXPECT_EQ(h.admittance.watches(), 1u);
  ASSERT_EQ(h.operator_panel.active(), 1u);
  EXPECT_EQ(h.operator_panel.newest()->spec.options, (std::vector<std::string>{"done", "abort"}));
  h.admittance.publish(guiding_state());  // a healthy state changes nothing
  ASSERT_TRUE(h.operator_panel.answer("done"));
  EXPECT_EQ(h.state(), "disengage");
  EXPECT_EQ(h.operator_panel.active(), 0u);
  EXPECT_EQ(h.crane.watches(), 0u);
  ASSERT_NE(h.admittance.pending(), nullptr);
  EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff);
  EXPECT_TRUE(h.admittance.pending()->stiffness.empty()) << "OFF goes back to the configured gains";
  EXPECT_FALSE(h.result) << "not before OFF is confirmed";
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  // The load moved where no camera saw it: the world model is told before the run succeeds.
  EXPECT_FALSE(h.result) << "not before the world model knows the load moved";
  const auto* update = h.world.pending_update();
  ASSERT_NE(update, nullptr);
  EXPECT_EQ(update->entity, "load");
  EXPECT_FALSE(update->localized);
  ASSERT_TRUE(h.world.answer_update(OpResult::success("ACCEPTED")));
  ASSERT_TRUE(h.succeeded());
  EXPECT_EQ(h.timers.pending(), 0u);
}

// (A world model that cannot be told the load moved fails the run: nothing may use the old pose.)
TEST_F(CollaborativeMoveLoadTest, ADurationEndsItWithoutAnAnswer) {
  params_["duration_s"] = 20.0;
  RunHarness h(type_, params_);
  to_guide(h);
  h.timers.advance(19s);
  EXPECT_EQ(h.state(), "guide");
  h.timers.advance(1s);
  EXPECT_EQ(h.state(), "disengage");
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  ASSERT_TRUE(h.world.answer_update(OpResult::failure("WORLD_UNREACHABLE", "no reply within 2000 ms")));
  // As every failure: admittance OFF confirmed first (it already is).
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  EXPECT_TRUE(h.failed_with("WORLD_UPDATE_FAILED"));
}

TEST_F(CollaborativeMoveLoadTest, NoAnswerWithinMaxDurationIsTimeoutAfterAdmittanceOff) {
  params_["max_duration_s"] = 30.0;
  RunHarness h(type_, params_);
  to_guide(h);
  h.timers.advance(30s);
  EXPECT_FALSE(h.result) << "reported before admittance OFF was confirmed";
  ASSERT_NE(h.admittance.pending(), nullptr);
  EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff);
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  EXPECT_TRUE(h.failed_with("TIMEOUT"));
}

TEST_F(CollaborativeMoveLoadTest, FailuresWhileGuidingStopFirstThenReportTheirCode) {
  struct Case {
    const char* name;
    std::function<void(RunHarness&)> cause;
    const char* code;
  };
  const std::vector<Case> cases = {
      {"abort", [](RunHarness& h) { h.operator_panel.answer("abort"); }, "OPERATOR_ABORTED"},
      {"crane", [](RunHarness& h) { h.crane.problem("crane: e-stop latched"); }, "CRANE_FAULT"},
      {"admittance fault",
       [](RunHarness& h) {
         auto s = guiding_state();
         s.fault = true;
         s.fault_code = "WRENCH_STALE";
         h.admittance.publish(s);
         h.timers.advance(kAdmittanceFaultGrace);
       },
       "ADMITTANCE_FAULT"},
      {"admittance crane fault",
       [](RunHarness& h) {
         auto s = guiding_state();
         s.fault = true;
         s.fault_code = "CRANE_FAULT";
         h.admittance.publish(s);
         h.timers.advance(kAdmittanceFaultGrace);
       },
       "CRANE_FAULT"},
      {"admittance went OFF on a crane fault",
       [](RunHarness& h) {
         auto s = guiding_state();
         s.mode = AdmittanceModeRequest::kOff;
         s.fault = true;
         s.fault_code = "CRANE_FAULT";
         h.admittance.publish(s);  // at once: the controller has already stopped
       },
       "CRANE_FAULT"},
      {"admittance went OFF on another fault",
       [](RunHarness& h) {
         auto s = guiding_state();
         s.mode = AdmittanceModeRequest::kOff;
         s.fault = true;
         s.fault_code = "COMMANDER_LOST";
         h.admittance.publish(s);
       },
       "ADMITTANCE_FAULT"},
      {"preempted",
       [](RunHarness& h) {
         auto s = guiding_state();
         s.mode = AdmittanceModeRequest::kOff;
         h.admittance.publish(s);
       },
       "ADMITTANCE_PREEMPTED"},
  };
  for (const auto& c : cases) {
    RunHarness h(type_, params_);
    to_guide(h);
    c.cause(h);
    EXPECT_FALSE(h.result) << c.name << ": reported before admittance OFF was confirmed";
    EXPECT_EQ(h.operator_panel.active(), 0u) << c.name;
    ASSERT_TRUE(h.admittance.complete(OpResult::success())) << c.name;
    EXPECT_TRUE(h.failed_with(c.code)) << c.name << " got " << (h.result ? h.result->code : "nothing");
    EXPECT_EQ(h.admittance.offs(), 1) << c.name;
  }
}

TEST_F(CollaborativeMoveLoadTest, AMomentaryAdmittanceFaultDoesNotEndTheMove) {
  RunHarness h(type_, params_);
  to_guide(h);
  auto s = guiding_state();
  s.fault = true;
  s.fault_code = "WRENCH_STALE";
  h.admittance.publish(s);
  h.timers.advance(kAdmittanceFaultGrace / 2);
  h.admittance.publish(guiding_state());
  h.timers.advance(kAdmittanceFaultGrace);
  EXPECT_FALSE(h.result);
  EXPECT_EQ(h.state(), "guide");
}

TEST_F(CollaborativeMoveLoadTest, AnUnhealthyCraneFailsThePreconditionWithoutCommandingAnything) {
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::failure(kCraneFault, "crane: fault 3")));
  ASSERT_TRUE(h.failed_with("CRANE_FAULT"));
  EXPECT_TRUE(h.admittance.requests.empty());
  EXPECT_EQ(h.crane.external_requests, 0);
}

TEST_F(CollaborativeMoveLoadTest, ExternalControlNotGrantedIsACraneFault) {
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_TRUE(h.crane.complete_external(OpResult::failure(kCraneFault, "not granted")));
  EXPECT_TRUE(h.failed_with("CRANE_FAULT"));
  EXPECT_TRUE(h.admittance.requests.empty());
}

TEST_F(CollaborativeMoveLoadTest, AnEngageThatIsNotConfirmedIsAnAdmittanceFaultAfterOff) {
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
  ASSERT_TRUE(h.admittance.complete(OpResult::failure("TIMEOUT", "no state")));
  EXPECT_FALSE(h.result);
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));  // the OFF of the safe stop
  EXPECT_TRUE(h.failed_with("ADMITTANCE_FAULT"));
}

TEST_F(CollaborativeMoveLoadTest, BadParamsAndMissingDevices) {
  for (const auto& params : {nlohmann::json{{"duration_s", -1}}, nlohmann::json{{"max_duration_s", 0}},
                             nlohmann::json{{"object", ""}}, nlohmann::json{{"speed", 1}}}) {
    RunHarness h(type_, params);
    h.run->start();
    EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << params.dump();
  }
  RunHarness h(type_, params_, [](Devices& d) { d.crane = nullptr; });
  h.run->start();
  EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE"));
}

TEST_F(CollaborativeMoveLoadTest, ShutdownInEveryStateReachesTheSafeStop) {
  // Resting states before anything moves: STOPPED at once, nothing commanded.
  for (const char* state : {"check_crane", "crane_external"}) {
    RunHarness h(type_, params_);
    h.run->start();
    if (std::string(state) == "crane_external") {
      ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    }
    ASSERT_EQ(h.state(), state);
    h.run->shutdown("test");
    EXPECT_TRUE(h.stopped()) << state;
    EXPECT_TRUE(h.admittance.requests.empty()) << state;
  }
  // engage, guide, disengage: STOPPED only once admittance OFF is confirmed; SAFE_STOP_FAILED otherwise.
  for (const char* state : {"engage", "guide", "disengage"}) {
    for (bool confirmed : {true, false}) {
      RunHarness h(type_, params_);
      h.run->start();
      ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
      ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
      if (std::string(state) != "engage") {
        ASSERT_TRUE(h.admittance.complete(OpResult::success()));
      }
      if (std::string(state) == "disengage") {
        ASSERT_TRUE(h.operator_panel.answer("done"));
      }
      ASSERT_EQ(h.state(), state);
      h.run->shutdown("test");
      EXPECT_FALSE(h.result) << state;
      ASSERT_NE(h.admittance.pending(), nullptr) << state;
      EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff) << state;
      ASSERT_TRUE(h.admittance.complete(confirmed ? OpResult::success() : OpResult::failure("TIMEOUT", "no OFF")));
      EXPECT_TRUE(confirmed ? h.stopped() : h.failed_with("SAFE_STOP_FAILED")) << state;
      EXPECT_EQ(h.operator_panel.active(), 0u) << state;
      EXPECT_EQ(h.timers.pending(), 0u) << state;
    }
  }
  // Every state's on_shutdown directly.
  RunHarness h(type_, params_);
  to_guide(h);
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_admittance_off(h));
}

}  // namespace
}  // namespace rigger::skill_executor
