// InsertVisuallyGuided's FSM on fakes: crane precondition, the insertion goal with stand-off, tracker
// continuous, the servo command, settling, every failure code, and shutdown from every state
// (admittance OFF + tracker stop, confirmed before STOPPED).
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "rigger/skill_sdk/states.hpp"
#include "skills/insert_visually_guided.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

nlohmann::json load_features(const std::string& target = "target") {
  return {{"insertion",
           {{"target", target}, {"pose_in_target", {{"position_m", {0.0, 0.0, 0.10}}, {"rpy_deg", {0, 0, 90}}}}}}};
}

AdmittanceSnapshot servo_state(double error_m, double error_rad, bool converged) {
  AdmittanceSnapshot s;
  s.mode = AdmittanceModeRequest::kRobotAndCrane;
  s.reference = AdmittanceReference::kVisualServo;
  s.servo_converged = converged;
  s.servo_error_m = error_m;
  s.servo_error_rad = error_rad;
  return s;
}

class InsertTest : public ::testing::Test {
 protected:
  SkillType type_{InsertVisuallyGuidedSkill::describe(), [] { return std::make_unique<InsertVisuallyGuidedSkill>(); }};
  nlohmann::json params_ = {{"standoff_z_m", 0.02}, {"settle_s", 1.0}, {"timeout_s", 60.0}, {"tracking_lost_s", 0.5}};

  void good_poses(RunHarness& h) {
    h.tracker.publish(h.tracker.sample("load", true, 0.9));
    h.tracker.publish(h.tracker.sample("target", true, 0.9));
  }
  /// Runs to `servo`.
  void to_servo(RunHarness& h) {
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_EQ(h.state(), "lookup");
    ASSERT_EQ(h.world.features_entity(), "load");
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features()));
    ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
    ASSERT_EQ(h.state(), "track");
    EXPECT_EQ(h.tracker.count(TrackerRequest::kContinuous), 2);
    good_poses(h);
    ASSERT_EQ(h.state(), "engage");
    ASSERT_TRUE(h.admittance.complete(OpResult::success()));
    ASSERT_EQ(h.state(), "servo");
  }
};

TEST_F(InsertTest, SuccessServoesSettlesThenHoldsWithAdmittanceOff) {
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features()));
  ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
  good_poses(h);
  ASSERT_EQ(h.state(), "engage");
  const AdmittanceRequest& r = h.admittance.requests.back();
  EXPECT_EQ(r.mode, AdmittanceModeRequest::kRobotAndCrane);
  EXPECT_EQ(r.reference, AdmittanceReference::kVisualServo);
  EXPECT_EQ(r.servo_object, "load");
  EXPECT_EQ(r.servo_target, "target");
  EXPECT_NEAR(r.servo_goal_in_target.translation().z(), 0.12, 1e-12) << "insertion offset + stand-off";
  EXPECT_NEAR(r.servo_goal_in_target.linear().col(0).y(), 1.0, 1e-9) << "yaw 90 deg kept";
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  ASSERT_EQ(h.state(), "servo");

  h.admittance.publish(servo_state(0.050, 0.1, false));
  h.timers.advance(300ms);
  good_poses(h);
  h.admittance.publish(servo_state(0.003, 0.01, true));  // within 5 mm, 1 deg: settling starts
  h.timers.advance(300ms);
  good_poses(h);
  h.admittance.publish(servo_state(0.007, 0.01, true));  // out again: settling restarts
  h.admittance.publish(servo_state(0.002, 0.01, true));
  h.timers.advance(400ms);
  good_poses(h);
  h.timers.advance(400ms);
  good_poses(h);
  EXPECT_EQ(h.state(), "servo") << "settled only 0.8 s";
  h.timers.advance(200ms);
  ASSERT_EQ(h.state(), "hold");
  EXPECT_GE(h.tracker.count(TrackerRequest::kStop, "load"), 1);
  EXPECT_GE(h.tracker.count(TrackerRequest::kStop, "target"), 1) << "the target's tracking is the skill's too";
  ASSERT_NE(h.admittance.pending(), nullptr);
  EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff);
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  ASSERT_TRUE(h.succeeded());
  EXPECT_NE(h.result->message.find("magnet on"), std::string::npos);
  EXPECT_EQ(h.timers.pending(), 0u);
  EXPECT_EQ(h.tracker.watches(), 0u);
  EXPECT_EQ(h.admittance.watches(), 0u);
  EXPECT_EQ(h.crane.watches(), 0u);
}

TEST_F(InsertTest, ConvergedButOutsideTheSkillsToleranceDoesNotSettle) {
  params_["tolerance_m"] = 0.001;
  RunHarness h(type_, params_);
  to_servo(h);
  h.admittance.publish(servo_state(0.003, 0.0, true));
  h.timers.advance(400ms);
  good_poses(h);
  h.timers.advance(400ms);
  good_poses(h);
  h.timers.advance(400ms);
  EXPECT_EQ(h.state(), "servo");
}

TEST_F(InsertTest, ServoFailuresStopFirstThenReportTheirCode) {
  struct Case {
    const char* name;
    std::function<void(RunHarness&)> cause;
    const char* code;
  };
  const auto fault = [](const char* code) {
    return [code](RunHarness& h) {
      auto s = servo_state(0.02, 0.0, false);
      s.fault = true;
      s.fault_code = code;
      h.admittance.publish(s);
      h.timers.advance(kAdmittanceFaultGrace / 2);  // the poses stay fresh: only the fault lasts
      h.tracker.publish(h.tracker.sample("load", true, 0.9));
      h.tracker.publish(h.tracker.sample("target", true, 0.9));
      h.timers.advance(kAdmittanceFaultGrace / 2);
    };
  };
  const std::vector<Case> cases = {
      {"crane state", [](RunHarness& h) { h.crane.problem("crane: no link"); }, "CRANE_FAULT"},
      {"admittance crane fault", fault("CRANE_FAULT"), "CRANE_FAULT"},
      {"admittance fault", fault("WRENCH_NOT_FINITE"), "ADMITTANCE_FAULT"},
      {"admittance went OFF on a crane fault",
       [](RunHarness& h) {
         auto s = servo_state(0.02, 0.0, false);
         s.mode = AdmittanceModeRequest::kOff;
         s.fault = true;
         s.fault_code = "CRANE_FAULT";
         h.admittance.publish(s);
       },
       "CRANE_FAULT"},
      {"preempted",
       [](RunHarness& h) {
         auto s = servo_state(0.02, 0.0, false);
         s.reference = AdmittanceReference::kJoystick;
         h.admittance.publish(s);
       },
       "ADMITTANCE_PREEMPTED"},
      {"tracker lost", [](RunHarness& h) { h.timers.advance(500ms); }, "TRACKING_LOST"},
      {"low quality",
       [](RunHarness& h) {
         h.timers.advance(300ms);
         h.tracker.publish(h.tracker.sample("load", true, 0.9));
         h.tracker.publish(h.tracker.sample("target", true, 0.2));  // below min_quality: not a refresh
         h.timers.advance(200ms);
       },
       "TRACKING_LOST"},
      {"servo stopped for tracking",
       [](RunHarness& h) {
         auto s = servo_state(0.02, 0.0, false);
         s.fault_code = "TARGET_POSE_STALE";
         h.admittance.publish(s);
         for (int i = 0; i < 5; ++i) {
           h.timers.advance(100ms);
           h.tracker.publish(h.tracker.sample("load", true, 0.9));
           h.tracker.publish(h.tracker.sample("target", true, 0.9));
           h.admittance.publish(s);
         }
       },
       "TRACKING_LOST"},
      {"timeout",
       [](RunHarness& h) {
         for (int i = 0; i < 60 * 4; ++i) {
           h.timers.advance(250ms);
           h.tracker.publish(h.tracker.sample("load", true, 0.9));
           h.tracker.publish(h.tracker.sample("target", true, 0.9));
         }
       },
       "TIMEOUT"},
  };
  for (const auto& c : cases) {
    RunHarness h(type_, params_);
    to_servo(h);
    const int stops_before = h.tracker.count(TrackerRequest::kStop);
    c.cause(h);
    ASSERT_FALSE(h.result) << c.name << ": reported before admittance OFF was confirmed";
    ASSERT_NE(h.admittance.pending(), nullptr) << c.name;
    EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff) << c.name;
    EXPECT_EQ(h.tracker.count(TrackerRequest::kStop), stops_before + 2) << c.name << ": load and target";
    ASSERT_TRUE(h.admittance.complete(OpResult::success())) << c.name;
    EXPECT_TRUE(h.failed_with(c.code)) << c.name << " got "
                                       << (h.result ? h.result->code + " " + h.result->message : "nothing");
  }
}

TEST_F(InsertTest, AServoStopForTrackingThatRecoversDoesNotFail) {
  RunHarness h(type_, params_);
  to_servo(h);
  auto s = servo_state(0.02, 0.0, false);
  s.fault_code = "LOAD_QUALITY_LOW";
  h.admittance.publish(s);
  h.timers.advance(300ms);
  good_poses(h);
  h.admittance.publish(servo_state(0.02, 0.0, false));
  h.timers.advance(300ms);
  good_poses(h);
  h.timers.advance(300ms);
  good_poses(h);
  // A momentary admittance fault (shorter than the grace) does not fail either.
  auto faulty = servo_state(0.02, 0.0, false);
  faulty.fault = true;
  faulty.fault_code = "WRENCH_STALE";
  h.admittance.publish(faulty);
  h.timers.advance(kAdmittanceFaultGrace / 2);
  good_poses(h);
  h.admittance.publish(servo_state(0.02, 0.0, false));
  h.timers.advance(kAdmittanceFaultGrace / 2);
  good_poses(h);
  h.timers.advance(kAdmittanceFaultGrace / 2);
  good_poses(h);
  EXPECT_FALSE(h.result);
  EXPECT_EQ(h.state(), "servo");
}

TEST_F(InsertTest, PreconditionAndLookupFailures) {
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::failure(kCraneFault, "crane: e-stop latched")));
    ASSERT_TRUE(h.failed_with("CRANE_FAULT"));
    EXPECT_TRUE(h.admittance.requests.empty());
    EXPECT_TRUE(h.tracker.commands.empty());
  }
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features("other")));
    ASSERT_TRUE(h.failed_with("UNKNOWN_FEATURE"));
    EXPECT_NE(h.result->message.find("'other'"), std::string::npos);
  }
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), nlohmann::json::object()));
    EXPECT_TRUE(h.failed_with("UNKNOWN_FEATURE"));
  }
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.world.answer_features(OpResult::failure("WORLD_UNREACHABLE", "no reply"), nlohmann::json::object()));
    EXPECT_TRUE(h.failed_with("WORLD_UNREACHABLE"));
  }
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features()));
    ASSERT_TRUE(h.crane.complete_external(OpResult::failure(kCraneFault, "not granted")));
    EXPECT_TRUE(h.failed_with("CRANE_FAULT"));
  }
  {  // no poses after TRACK_CONTINUOUS: TRACKING_LOST after the tracker is stopped
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features()));
    ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
    h.tracker.publish(h.tracker.sample("load", true, 0.9));
    h.timers.advance(InsertVisuallyGuidedSkill::kTrackStartTimeout);
    ASSERT_TRUE(h.failed_with("TRACKING_LOST"));
    EXPECT_NE(h.result->message.find("target"), std::string::npos);
    EXPECT_EQ(h.tracker.count(TrackerRequest::kStop, "load"), 1);
    EXPECT_EQ(h.tracker.count(TrackerRequest::kStop, "target"), 1);
    EXPECT_TRUE(h.admittance.requests.empty());
  }
}

TEST_F(InsertTest, BadParamsAndMissingDevices) {
  for (const auto& params :
       {nlohmann::json{{"tolerance_m", 0.2}}, nlohmann::json{{"standoff_z_m", 2.0}}, nlohmann::json{{"settle_s", -1}},
        nlohmann::json{{"object", "target"}}, nlohmann::json{{"tolerance_rad", {{"value", 30}, {"unit", "deg"}}}}}) {
    RunHarness h(type_, params);
    h.run->start();
    EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << params.dump();
    EXPECT_TRUE(h.admittance.requests.empty());
  }
  // A quantity in degrees is converted.
  RunHarness ok(type_, {{"tolerance_rad", {{"value", 2}, {"unit", "deg"}}}});
  ok.run->start();
  EXPECT_FALSE(ok.result);
  for (int which = 0; which < 4; ++which) {
    RunHarness h(type_, params_, [which](Devices& d) {
      if (which == 0) d.admittance = nullptr;
      if (which == 1) d.crane = nullptr;
      if (which == 2) d.tracker = nullptr;
      if (which == 3) d.world_access = nullptr;
    });
    h.run->start();
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << which;
  }
}

TEST_F(InsertTest, ShutdownInEveryStateReachesTheSafeStop) {
  const std::vector<std::string> states = {"check_crane", "lookup", "crane_external", "track", "engage",
                                           "servo",       "hold"};
  for (const auto& state : states) {
    for (bool confirmed : {true, false}) {
      RunHarness h(type_, params_);
      h.run->start();
      if (h.state() != state) {
        ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
      }
      if (h.state() != state) {
        ASSERT_TRUE(h.world.answer_features(OpResult::success(), load_features()));
      }
      if (h.state() != state) {
        ASSERT_TRUE(h.crane.complete_external(OpResult::success()));
      }
      if (h.state() != state) good_poses(h);
      if (h.state() != state) {
        ASSERT_TRUE(h.admittance.complete(OpResult::success()));
      }
      if (h.state() != state) {
        h.admittance.publish(servo_state(0.001, 0.0, true));
        for (int i = 0; i < 4; ++i) {  // settle (1 s) with the poses kept fresh
          h.timers.advance(250ms);
          good_poses(h);
        }
      }
      ASSERT_EQ(h.state(), state);
      const auto commanded_before = h.admittance.requests.size();
      const int stops_before = h.tracker.count(TrackerRequest::kStop);
      h.run->shutdown("test");
      const bool moves = state == "engage" || state == "servo" || state == "hold";
      if (moves) {
        EXPECT_FALSE(h.result) << state << ": STOPPED before admittance OFF was confirmed";
        ASSERT_EQ(h.admittance.requests.size(), commanded_before + 1) << state;
        EXPECT_EQ(h.admittance.requests.back().mode, AdmittanceModeRequest::kOff) << state;
        EXPECT_EQ(h.tracker.count(TrackerRequest::kStop), stops_before + 2) << state << ": load and target";
        ASSERT_TRUE(h.admittance.complete(confirmed ? OpResult::success() : OpResult::failure("TIMEOUT", "no OFF")));
        EXPECT_TRUE(confirmed ? h.stopped() : h.failed_with("SAFE_STOP_FAILED")) << state;
      } else {
        EXPECT_TRUE(h.stopped()) << state;
        EXPECT_EQ(h.admittance.requests.size(), commanded_before) << state;
        EXPECT_EQ(h.tracker.count(TrackerRequest::kStop), stops_before + (state == "track" ? 2 : 0)) << state;
      }
      EXPECT_EQ(h.timers.pending(), 0u) << state;
      EXPECT_EQ(h.tracker.watches(), 0u) << state;
    }
  }
  // Every state's on_shutdown directly: safe, and only after OFF is confirmed where one is sent.
  RunHarness h(type_, params_);
  to_servo(h);
  EXPECT_EQ(h.run->skill()->state_names(), states);
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_admittance_off(h));
}

TEST(InsertionGoal, AddsTheStandOffInTheTargetFrame) {
  Eigen::Isometry3d goal;
  ASSERT_FALSE(insertion_goal(load_features(), "target", Eigen::Vector3d(0.01, 0, 0.05), goal));
  EXPECT_NEAR(goal.translation().x(), 0.01, 1e-12);
  EXPECT_NEAR(goal.translation().z(), 0.15, 1e-12);
  EXPECT_TRUE(insertion_goal(load_features(), "other", Eigen::Vector3d::Zero(), goal));
  EXPECT_TRUE(insertion_goal({{"insertion", {{"target", "target"}}}}, "target", Eigen::Vector3d::Zero(), goal));
}

}  // namespace
}  // namespace rigger::skill_executor

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

// PAUSE during the servo: admittance OFF (robot and crane at rest, the tracker keeps tracking), no
// servo timer runs out while paused (TRACKING_LOST, TIMEOUT); RESUME engages the servo again and the
// insertion settles and succeeds as usual.
TEST_F(InsertTest, APauseTurnsAdmittanceOffAndResumeEngagesTheServoAgain) {
  EXPECT_TRUE(InsertVisuallyGuidedSkill::describe().pausable);
  RunHarness h(type_, params_);
  to_servo(h);
  const int tracker_stops = h.tracker.count(TrackerRequest::kStop);
  ASSERT_TRUE(h.run->pause(true));
  ASSERT_NE(h.admittance.pending(), nullptr);
  EXPECT_EQ(h.admittance.pending()->mode, AdmittanceModeRequest::kOff);
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  EXPECT_EQ(h.tracker.count(TrackerRequest::kStop), tracker_stops) << "the tracker was stopped by the pause";
  h.timers.advance(120s);  // past tracking_lost_s and timeout_s, no poses
  EXPECT_FALSE(h.result) << h.result->code << ": " << h.result->message;
  EXPECT_EQ(h.admittance.watches(), 0u) << "the servo state is left while paused";

  ASSERT_TRUE(h.run->pause(false));
  ASSERT_EQ(h.state(), "engage");
  ASSERT_NE(h.admittance.pending(), nullptr);
  EXPECT_EQ(h.admittance.pending()->reference, AdmittanceReference::kVisualServo);
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  ASSERT_EQ(h.state(), "servo");
  good_poses(h);
  h.admittance.publish(servo_state(0.002, 0.01, true));
  h.timers.advance(400ms);
  good_poses(h);
  h.timers.advance(400ms);
  good_poses(h);
  h.timers.advance(300ms);
  ASSERT_EQ(h.state(), "hold");
  ASSERT_TRUE(h.admittance.complete(OpResult::success()));
  EXPECT_TRUE(h.succeeded());
}

}  // namespace
}  // namespace rigger::skill_executor
