// AttachRobotToLoad's FSM on fakes: the success path (what is commanded), the retry after a slip, each
// failure code, bad params, and a shutdown from every state reaching its safe stop without touching
// the magnet.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "tool_poses.hpp"
#include "skills/attach_robot_to_load.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::FakeGripper;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

// grasp_side and pre_grasp of the simulated cell in the robot base frame.
const Eigen::Isometry3d kGrasp = tool_facing_x(0.80, -0.25, 0.30);
const Eigen::Isometry3d kApproach = tool_facing_x(0.70, -0.25, 0.30);

nlohmann::json attach_params() {
  return {{"grasp", "load/grasp_side"}, {"approach", "load/pre_grasp"}, {"timeout_s", 30.0}};
}

class AttachTest : public ::testing::Test {
 protected:
  SkillType type_{AttachRobotToLoadSkill::describe(), [] { return std::make_unique<AttachRobotToLoadSkill>(); }};

  /// Starts the run and answers SkillRun's own feature resolutions (in the world frame).
  static void start(RunHarness& h) {
    h.run->start();
    while (!h.run->skill() && !h.result && h.resolver.pending() > 0) h.resolver.answer(OpResult::success());
  }

  /// Completes what the current state waits for, as on the success path. `grasp_now` is what the
  /// resolver answers for the grasp frame.
  static void step(RunHarness& h, const Eigen::Isometry3d& grasp_now = kGrasp,
                   const GripperSnapshot& initial = FakeGripper::state(false, false)) {
    const std::string s = h.state();
    if (s == "check" || s == "re_resolve") {
      if (h.crane.pending_checks() > 0)
        ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
      else if (h.gripper.pending_waits() > 0)
        ASSERT_EQ(h.gripper.publish(initial), 1);
      else
        ASSERT_TRUE(answer_feature(h, grasp_now));
    } else if (s == "resolve") {
      ASSERT_TRUE(answer_feature(h, grasp_now));
    } else if (s == "release") {
      if (h.gripper.pending_command())
        ASSERT_TRUE(h.gripper.confirm());
      else
        ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
    } else if (s == "retreat" || s == "move_approach" || s == "approach") {
      ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
    } else if (s == "energize") {
      ASSERT_TRUE(h.gripper.confirm());
    } else if (s == "await_hold" || s == "confirm") {
      ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 1);
    } else if (s == "verify") {
      ASSERT_TRUE(h.gripper.time_out_wait());
    } else {
      FAIL() << "no step for state " << s;
    }
  }
  static bool answer_feature(RunHarness& h, const Eigen::Isometry3d& grasp_now) {
    const auto* req = h.resolver.oldest();
    if (!req) return false;
    EXPECT_EQ(req->frame, kRobotBaseFrame) << req->ref;
    const bool grasp = req->ref == "load/grasp_side";
    return h.resolver.answer(OpResult::success(), grasp ? grasp_now : kApproach);
  }
  /// Drives the run along the success path (or the retry path when `initial` is energized) until it
  /// enters `target` (or ends).
  static void drive_to(RunHarness& h, const std::string& target,
                       const GripperSnapshot& initial = FakeGripper::state(false, false)) {
    run_steps::drive_to(h, target, [initial](RunHarness& r) { step(r, kGrasp, initial); }, 40);
  }
  static void run_to_end(RunHarness& h, const GripperSnapshot& initial = FakeGripper::state(false, false)) {
    run_steps::run_to_end(h, [initial](RunHarness& r) { step(r, kGrasp, initial); }, 40);
  }
};

TEST_F(AttachTest, SuccessMovesToTheApproachEnergizesApproachesSlowlyAndVerifiesTheHold) {
  RunHarness h(type_, attach_params());
  start(h);
  ASSERT_NE(h.run->skill(), nullptr);
  drive_to(h, "move_approach");
  auto* transfer = h.robot.pending(Kind::kMove);
  ASSERT_NE(transfer, nullptr);
  EXPECT_EQ(transfer->goal.frame, kRobotBaseFrame);
  EXPECT_EQ(transfer->goal.kind, MotionGoal::Kind::kCartesian);
  EXPECT_TRUE(transfer->goal.pose_frame_tool.isApprox(kApproach, 1e-12));
  EXPECT_NEAR(transfer->goal.speed_scale, 0.2, 1e-12);
  EXPECT_EQ(transfer->timeout, 30s);
  EXPECT_TRUE(h.gripper.commanded.empty()) << "the magnet is energized only at the approach pose";
  drive_to(h, "approach");
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{true});
  auto* approach = h.robot.pending(Kind::kMove);
  ASSERT_NE(approach, nullptr);
  // The straight approach aims press_in_m (default 10 mm) past the grasp frame, along the tool z.
  const Eigen::Isometry3d pressed_in = kGrasp * Eigen::Translation3d(0.0, 0.0, 0.01);
  EXPECT_TRUE(approach->goal.pose_frame_tool.isApprox(pressed_in, 1e-12));
  EXPECT_NEAR(approach->goal.speed_scale, 0.02 / kRobotMaxToolSpeedMps, 1e-12);  // approach_speed default 0.02 m/s
  drive_to(h, "verify");
  ASSERT_NE(h.gripper.oldest_wait(), nullptr);
  EXPECT_EQ(h.gripper.oldest_wait()->timeout, 1s);  // verify_s default
  run_to_end(h);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 2);
  EXPECT_EQ(h.robot.stops, 0);
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{true});
  ASSERT_FALSE(h.progress.empty());
  EXPECT_LT(h.progress.front().first, h.progress.back().first);
}

TEST_F(AttachTest, TheGraspIsReResolvedBeforeTheFinalApproachAndTheNewPoseIsUsed) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "re_resolve");
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_NE(h.resolver.oldest(), nullptr);
  EXPECT_EQ(h.resolver.oldest()->ref, "load/grasp_side");
  Eigen::Isometry3d swayed = kGrasp;
  swayed.translation().y() += 0.012;  // 12 mm of sway, within max_sway_m = 30 mm
  ASSERT_TRUE(h.resolver.answer(OpResult::success(), swayed));
  ASSERT_EQ(h.state(), "approach");
  EXPECT_NEAR(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().y(), -0.238, 1e-9);
}

TEST_F(AttachTest, TooMuchSwayIsLoadMovingWithoutApproaching) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "re_resolve");
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  Eigen::Isometry3d swayed = kGrasp;
  swayed.translation().y() += 0.05;
  ASSERT_TRUE(h.resolver.answer(OpResult::success(), swayed));
  EXPECT_TRUE(h.failed_with("LOAD_MOVING")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 1);
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{true}) << "the magnet stays as it is";
}

TEST_F(AttachTest, ARetryAfterASlipReleasesAndRetreatsToTheApproachPoseFirst) {
  RunHarness h(type_, attach_params());
  start(h);
  const GripperSnapshot slipped = FakeGripper::state(true, false, true);
  drive_to(h, "retreat", slipped);
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{false});
  auto* retreat = h.robot.pending(Kind::kMove);
  ASSERT_NE(retreat, nullptr);
  EXPECT_TRUE(retreat->goal.pose_frame_tool.isApprox(kApproach, 1e-12));
  EXPECT_NEAR(retreat->goal.speed_scale, 0.02 / kRobotMaxToolSpeedMps, 1e-12);
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  EXPECT_EQ(h.state(), "energize") << "already at the approach pose";
  run_to_end(h, slipped);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.gripper.commanded, (std::vector<bool>{false, true}));
  EXPECT_EQ(h.robot.moves, 2);
}

TEST_F(AttachTest, AGripperThatStaysEnergizedAfterTheReleaseIsReleaseFailed) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "release", FakeGripper::state(true, true));
  ASSERT_TRUE(h.gripper.confirm());
  EXPECT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 0) << "still holding: not released";
  ASSERT_TRUE(h.gripper.time_out_wait());
  EXPECT_TRUE(h.failed_with("RELEASE_FAILED")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(AttachTest, ALossWhileVerifyingIsGraspLost) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "verify");
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 0) << "holding is no news";
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, false, true)), 1);
  EXPECT_TRUE(h.failed_with("GRASP_LOST")) << h.describe_result();
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{true}) << "never released by the skill";
  EXPECT_EQ(h.robot.stops, 0) << "the robot is at rest in verify";
}

TEST_F(AttachTest, ALossSeenByTheConfirmingSampleIsGraspLost) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "confirm");
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, false)), 1);
  EXPECT_TRUE(h.failed_with("GRASP_LOST")) << h.describe_result();
}

TEST_F(AttachTest, NoHoldAfterTheApproachIsGraspFailed) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "await_hold");
  EXPECT_EQ(h.gripper.oldest_wait()->timeout, 2s);  // hold_timeout_s default
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, false, true)), 0);
  ASSERT_TRUE(h.gripper.time_out_wait());
  EXPECT_TRUE(h.failed_with("GRASP_FAILED")) << h.describe_result();
}

TEST_F(AttachTest, ResolverFailuresEndTheRunWithTheirCodeBeforeAnyMotion) {
  for (const char* code : {"UNKNOWN_FEATURE", "WORLD_UNREACHABLE"}) {
    RunHarness h(type_, attach_params());
    start(h);
    drive_to(h, "resolve");
    ASSERT_TRUE(h.resolver.answer(OpResult::failure(code, "test")));
    EXPECT_TRUE(h.failed_with(code)) << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
}

TEST_F(AttachTest, AnUnlocalizedLoadIsNotLocalized) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "resolve");
  h.resolver.localized = false;
  ASSERT_TRUE(h.resolver.answer(OpResult::success(), kGrasp));
  EXPECT_TRUE(h.failed_with("NOT_LOCALIZED")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(AttachTest, AnApproachFarFromTheGraspOrOutOfReachIsPlanFailed) {
  for (const auto& approach : {tool_facing_x(0.0, -0.25, 0.30), tool_facing_x(1.5, -0.25, 0.30)}) {
    RunHarness h(type_, attach_params());
    start(h);
    drive_to(h, "resolve");
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), kGrasp));
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), approach));
    EXPECT_TRUE(h.failed_with("PLAN_FAILED")) << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
}

TEST_F(AttachTest, AFailedMotionStopsTheRobotBeforeReportingIt) {
  for (const char* state : {"move_approach", "approach"}) {
    RunHarness h(type_, attach_params());
    start(h);
    drive_to(h, state);
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("MOTION_FAILED", "path not trackable")));
    EXPECT_FALSE(h.result) << "reported before the robot stopped";
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("MOTION_FAILED")) << state << ": " << h.describe_result();
  }
}

TEST_F(AttachTest, TheOverallTimeoutFailsTimeoutFromWhereverTheRunIs) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "approach");
  h.timers.advance(30s);
  EXPECT_FALSE(h.result) << "reported before the robot stopped";
  EXPECT_EQ(h.robot.stops, 1);
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  EXPECT_TRUE(h.failed_with("TIMEOUT")) << h.describe_result();
  // A motion that times out by itself is TIMEOUT too.
  RunHarness h2(type_, attach_params());
  start(h2);
  drive_to(h2, "move_approach");
  ASSERT_TRUE(h2.robot.complete(Kind::kMove, OpResult::failure("TIMEOUT", "too slow")));
  ASSERT_TRUE(h2.robot.complete(Kind::kStop, OpResult::success()));
  EXPECT_TRUE(h2.failed_with("TIMEOUT")) << h2.describe_result();
}

TEST_F(AttachTest, ACraneFaultRefusesToMove) {
  RunHarness h(type_, attach_params());
  start(h);
  ASSERT_EQ(h.state(), "check");
  ASSERT_TRUE(h.crane.complete_check(OpResult::failure("CRANE_FAULT", "PLC fault 17")));
  EXPECT_TRUE(h.failed_with("CRANE_FAULT")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
  // And right before the final approach.
  RunHarness h2(type_, attach_params());
  start(h2);
  drive_to(h2, "re_resolve");
  ASSERT_TRUE(h2.crane.complete_check(OpResult::failure("CRANE_FAULT", "e-stop")));
  EXPECT_TRUE(h2.failed_with("CRANE_FAULT")) << h2.describe_result();
  EXPECT_EQ(h2.robot.moves, 1);
}

TEST_F(AttachTest, ACraneFaultWhileTheRobotMovesStopsItAndFailsCraneFault) {
  for (const char* state : {"move_approach", "approach"}) {
    RunHarness h(type_, attach_params());
    start(h);
    drive_to(h, state);
    ASSERT_EQ(h.crane.watches(), 1u) << state;
    ASSERT_EQ(h.crane.problem("PLC link down"), 1u);
    EXPECT_FALSE(h.result) << "reported before the robot stopped";
    EXPECT_EQ(h.robot.stops, 1);
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("CRANE_FAULT")) << state << ": " << h.describe_result();
  }
  // The watch ends with its state.
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "energize");
  EXPECT_EQ(h.crane.watches(), 0u);
}

TEST_F(AttachTest, MissingDevicesAreDeviceUnavailableAndCheckCraneFalseSkipsTheCrane) {
  {
    RunHarness h(type_, attach_params(), [](Devices& d) { d.gripper = nullptr; });
    start(h);
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << h.describe_result();
  }
  {
    RunHarness h(type_, attach_params(), [](Devices& d) { d.crane = nullptr; });
    start(h);
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << h.describe_result();
    EXPECT_NE(h.result->message.find("crane"), std::string::npos);
  }
  {
    auto params = attach_params();
    params["check_crane"] = false;
    RunHarness h(type_, params, [](Devices& d) { d.crane = nullptr; });
    start(h);
    EXPECT_FALSE(h.result);
    EXPECT_EQ(h.gripper.pending_waits(), 1u) << "straight to the gripper state";
  }
}

TEST_F(AttachTest, NoGripperStateIsGripperStateStaleAndAnUnconfirmedEnergizeIsGripperTimeout) {
  RunHarness h(type_, attach_params());
  start(h);
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_TRUE(h.gripper.time_out_wait());
  EXPECT_TRUE(h.failed_with("GRIPPER_STATE_STALE")) << h.describe_result();

  RunHarness h2(type_, attach_params());
  start(h2);
  drive_to(h2, "energize");
  ASSERT_TRUE(h2.gripper.confirm(OpResult::failure("TIMEOUT", "no state")));
  EXPECT_TRUE(h2.failed_with("GRIPPER_TIMEOUT")) << h2.describe_result();
}

TEST_F(AttachTest, BadParamsFailBeforeAnything) {
  auto params = attach_params();
  params["approach_speed_m_per_s"] = 0.5;
  params.erase("grasp");
  RunHarness h(type_, params);
  h.run->start();
  ASSERT_TRUE(h.failed_with("BAD_PARAMS")) << h.describe_result();
  EXPECT_NE(h.result->message.find("/params/approach_speed_m_per_s"), std::string::npos) << h.result->message;
  EXPECT_NE(h.result->message.find("/params/grasp"), std::string::npos) << h.result->message;
  EXPECT_EQ(h.robot.moves, 0);
  EXPECT_TRUE(h.gripper.commanded.empty());
}

TEST_F(AttachTest, ShutdownInEveryStateReachesItsSafeStopAndNeverTouchesTheMagnet) {
  run_steps::expect_shutdown_in_each_state(
      type_, attach_params(),
      {"check", "resolve", "release", "retreat", "move_approach", "energize", "re_resolve", "approach", "await_hold",
       "verify", "confirm"},
      {"retreat", "move_approach", "approach"}, [](RunHarness& h, const std::string& state) {
        start(h);
        const bool retry_path = state == "release" || state == "retreat";
        drive_to(h, state, retry_path ? FakeGripper::state(true, true) : FakeGripper::state(false, false));
      });
}

TEST_F(AttachTest, AStopThatIsNotConfirmedIsSafeStopFailed) {
  RunHarness h(type_, attach_params());
  start(h);
  drive_to(h, "approach");
  h.run->shutdown("test");
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::failure("TIMEOUT", "no rest within 3 s")));
  EXPECT_TRUE(h.failed_with("SAFE_STOP_FAILED")) << h.describe_result();
}

TEST_F(AttachTest, EveryStatesSafeStopReportsSafe) {
  RunHarness h(type_, attach_params());
  start(h);
  const Skill& skill = *h.run->skill();
  EXPECT_EQ(skill.state_names(),
            (std::vector<std::string>{"check", "resolve", "release", "retreat", "move_approach", "energize",
                                      "re_resolve", "approach", "await_hold", "verify", "confirm"}));
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_robot_stop(h));
  EXPECT_EQ(h.robot.stops, 3) << "retreat, move_approach and approach command the robot";
  EXPECT_TRUE(h.gripper.commanded.empty());
}

TEST(GripperSkillPlanning, StraightApproachChecks) {
  EXPECT_FALSE(check_straight_approach(kApproach, kGrasp, 1.2, 0.5, 0.1));
  EXPECT_TRUE(check_straight_approach(kApproach, kGrasp, 0.5, 0.5, 0.1));   // beyond reach
  EXPECT_TRUE(check_straight_approach(kApproach, kGrasp, 1.2, 0.05, 0.1));  // too long
  Eigen::Isometry3d turned = kGrasp;
  turned.linear() = turned.linear() * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_TRUE(check_straight_approach(kApproach, turned, 1.2, 0.5, 0.1));
  EXPECT_NEAR(along_tool_z(kGrasp, -0.1).translation().x(), 0.70, 1e-12);  // tool z = base +x
  EXPECT_NEAR(speed_scale_for(0.05), 0.1, 1e-12);
  EXPECT_NEAR(speed_scale_for(5.0), 1.0, 1e-12);
}

}  // namespace
}  // namespace rigger::skill_executor
