// Release's FSM on fakes: success (de-energize, confirmed, retreat along the tool -z), each failure
// code, bad params, and a shutdown from every state.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "tool_poses.hpp"
#include "skills/release.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::FakeGripper;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

const Eigen::Isometry3d kTool = tool_facing_x(0.80, -0.25, 0.30);

RobotSnapshot robot_at(const Eigen::Isometry3d& pose, std::string frame = kRobotBaseFrame) {
  RobotSnapshot s;
  s.frame = std::move(frame);
  s.tool_pose = pose;
  return s;
}

class ReleaseTest : public ::testing::Test {
 protected:
  SkillType type_{ReleaseSkill::describe(), [] { return std::make_unique<ReleaseSkill>(); }};

  /// Completes what the current state waits for, as on the success path.
  static void step(RunHarness& h) {
    const std::string s = h.state();
    if (s == "check") {
      if (h.crane.pending_checks() > 0)
        ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
      else
        ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 1);
    } else if (s == "release") {
      ASSERT_TRUE(h.gripper.confirm());
    } else if (s == "confirm_released") {
      ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
    } else if (s == "read_pose") {
      ASSERT_TRUE(h.robot.answer_state(robot_at(kTool)));
    } else if (s == "retreat") {
      ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
    } else {
      FAIL() << "no step for state " << s;
    }
  }
  static void drive_to(RunHarness& h, const std::string& target) { run_steps::drive_to(h, target, step); }
};

TEST_F(ReleaseTest, ReleasesConfirmsAndRetreatsAlongTheToolMinusZ) {
  RunHarness h(type_, nlohmann::json::object());
  h.run->start();
  drive_to(h, "retreat");
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{false});
  auto* retreat = h.robot.pending(Kind::kMove);
  ASSERT_NE(retreat, nullptr);
  EXPECT_EQ(retreat->goal.frame, kRobotBaseFrame);
  // The tool z points along the base +x: 0.10 m back along -z is x - 0.10, orientation kept.
  EXPECT_NEAR(retreat->goal.pose_frame_tool.translation().x(), 0.70, 1e-12);
  EXPECT_NEAR(retreat->goal.pose_frame_tool.translation().y(), -0.25, 1e-12);
  EXPECT_TRUE(retreat->goal.pose_frame_tool.linear().isApprox(kTool.linear(), 1e-12));
  EXPECT_NEAR(retreat->goal.speed_scale, 0.05 / kRobotMaxToolSpeedMps, 1e-12);
  EXPECT_EQ(retreat->timeout, 30s);
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.robot.stops, 0);
}

TEST_F(ReleaseTest, AZeroRetreatSucceedsOnceReleased) {
  RunHarness h(type_, {{"retreat_m", 0.0}});
  h.run->start();
  drive_to(h, "confirm_released");
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(ReleaseTest, AnEnergizedGripperHoldingNothingIsReleasedToo) {
  RunHarness h(type_, {{"retreat_m", 0.0}});
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, false)), 1);
  EXPECT_EQ(h.state(), "release");
}

TEST_F(ReleaseTest, NothingHeldIsNotHolding) {
  RunHarness h(type_, nlohmann::json::object());
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
  EXPECT_TRUE(h.failed_with("NOT_HOLDING")) << h.describe_result();
  EXPECT_TRUE(h.gripper.commanded.empty());
}

TEST_F(ReleaseTest, ACraneFaultRefusesToLetGo) {
  RunHarness h(type_, nlohmann::json::object());
  h.run->start();
  ASSERT_TRUE(h.crane.complete_check(OpResult::failure("CRANE_FAULT", "overload")));
  EXPECT_TRUE(h.failed_with("CRANE_FAULT")) << h.describe_result();
  EXPECT_TRUE(h.gripper.commanded.empty());
}

TEST_F(ReleaseTest, GripperFailuresHaveTheirCodes) {
  {
    RunHarness h(type_, nlohmann::json::object());
    h.run->start();
    ASSERT_TRUE(h.crane.complete_check(OpResult::success()));
    ASSERT_TRUE(h.gripper.time_out_wait());
    EXPECT_TRUE(h.failed_with("GRIPPER_STATE_STALE")) << h.describe_result();
  }
  {
    RunHarness h(type_, nlohmann::json::object());
    h.run->start();
    drive_to(h, "release");
    ASSERT_TRUE(h.gripper.confirm(OpResult::failure("TIMEOUT", "no state")));
    EXPECT_TRUE(h.failed_with("GRIPPER_TIMEOUT")) << h.describe_result();
  }
  {
    RunHarness h(type_, nlohmann::json::object());
    h.run->start();
    drive_to(h, "confirm_released");
    EXPECT_EQ(h.gripper.publish(FakeGripper::state(false, true)), 0) << "still holding";
    ASSERT_TRUE(h.gripper.time_out_wait());
    EXPECT_TRUE(h.failed_with("RELEASE_FAILED")) << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
}

TEST_F(ReleaseTest, RobotStateFailuresHaveTheirCodes) {
  struct Case {
    std::optional<RobotSnapshot> state;
    const char* code;
  };
  RobotSnapshot faulted = robot_at(kTool);
  faulted.fault = "emergency_stop";
  for (const auto& c :
       {Case{std::nullopt, "ROBOT_STATE_STALE"}, Case{robot_at(kTool, "world"), "NOT_VERIFIABLE"},
        Case{faulted, "ROBOT_FAULT"}, Case{robot_at(tool_facing_x(1.4, 0.0, 0.2)), "PLAN_FAILED"}}) {
    RunHarness h(type_, nlohmann::json::object());
    h.run->start();
    drive_to(h, "read_pose");
    ASSERT_TRUE(h.robot.answer_state(c.state));
    EXPECT_TRUE(h.failed_with(c.code)) << c.code << ": " << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
}

TEST_F(ReleaseTest, AFailedRetreatStopsTheRobotFirstAndTheOverallTimeoutIsTimeout) {
  {
    RunHarness h(type_, nlohmann::json::object());
    h.run->start();
    drive_to(h, "retreat");
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("MOTION_ABORTED", "STOPPED: stopped by other")));
    EXPECT_FALSE(h.result);
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("MOTION_ABORTED")) << h.describe_result();
  }
  {
    RunHarness h(type_, {{"timeout_s", 5.0}});
    h.run->start();
    drive_to(h, "retreat");
    h.timers.advance(5s);
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("TIMEOUT")) << h.describe_result();
  }
}

TEST_F(ReleaseTest, BadParamsAndMissingDevices) {
  {
    RunHarness h(type_, {{"retreat_m", -0.1}});
    h.run->start();
    EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << h.describe_result();
    EXPECT_NE(h.result->message.find("/params/retreat_m"), std::string::npos);
  }
  {
    RunHarness h(type_, nlohmann::json::object(), [](Devices& d) { d.robot = nullptr; });
    h.run->start();
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << h.describe_result();
  }
}

TEST_F(ReleaseTest, ShutdownInEveryStateReachesItsSafeStop) {
  run_steps::expect_shutdown_in_each_state(type_, nlohmann::json::object(),
                                           {"check", "release", "confirm_released", "read_pose", "retreat"},
                                           {"retreat"}, [](RunHarness& h, const std::string& state) {
                                             h.run->start();
                                             drive_to(h, state);
                                           });
  RunHarness h(type_, nlohmann::json::object());
  h.run->start();
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_robot_stop(h));
  EXPECT_EQ(h.robot.stops, 1) << "only retreat commands the robot";
}

}  // namespace
}  // namespace rigger::skill_executor
