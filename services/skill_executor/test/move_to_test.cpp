// MoveTo's FSM on fake primitives: the success path, each failure path, and a shutdown from every
// state reaching the safe stop.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "skills/move_to.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

nlohmann::json goal_params(double x = 0.5, double y = 0.1, double z = 0.4) {
  return {{"goal", {{"position_m", {x, y, z}}, {"rpy_deg", {180.0, 0.0, 90.0}}}}, {"timeout_s", 10.0}};
}

RobotSnapshot at(double x, double y, double z, std::string frame = kRobotBaseFrame) {
  RobotSnapshot s;
  s.frame = std::move(frame);
  s.tool_pose.translation() = Eigen::Vector3d(x, y, z);
  return s;
}

class MoveToTest : public ::testing::Test {
 protected:
  SkillType type_{MoveToSkill::describe(), [] { return std::make_unique<MoveToSkill>(); }};
};

TEST_F(MoveToTest, SuccessPathPlansMovesAndVerifies) {
  RunHarness h(type_, goal_params());
  h.run->start();
  EXPECT_EQ(h.run->skill()->state(), "move");
  auto* move = h.robot.pending(Kind::kMove);
  ASSERT_NE(move, nullptr);
  EXPECT_EQ(move->goal.frame, kRobotBaseFrame);
  EXPECT_NEAR(move->goal.pose_frame_tool.translation().x(), 0.5, 1e-12);
  EXPECT_NEAR(move->goal.speed_scale, 0.2, 1e-12);  // the default
  EXPECT_EQ(move->timeout, 10s);
  // rpy (180, 0, 90): the tool's z axis points down.
  EXPECT_NEAR(move->goal.pose_frame_tool.linear().col(2).z(), -1.0, 1e-9);
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  EXPECT_EQ(h.run->skill()->state(), "verify");
  ASSERT_TRUE(h.robot.answer_state(at(0.502, 0.1, 0.4)));  // 2 mm off, tolerance 5 mm
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(h.robot.stops, 0);
  ASSERT_GE(h.progress.size(), 2u);
  EXPECT_LT(h.progress.front().first, h.progress.back().first);
}

TEST_F(MoveToTest, AGoalOutOfReachFailsInPlanWithoutMoving) {
  RunHarness h(type_, goal_params(2.0, 0.0, 0.5));
  h.run->start();
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "PLAN_FAILED");
  EXPECT_NE(h.result->message.find("reach"), std::string::npos);
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(MoveToTest, AGoalInAnotherFrameIsRefusedByThePlanner) {
  auto params = goal_params();
  params["goal"]["frame"] = "world";
  RunHarness h(type_, params);
  h.run->start();
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "PLAN_FAILED");
  EXPECT_NE(h.result->message.find("'world'"), std::string::npos) << h.result->message;
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(MoveToTest, AGoalNamingTheRobotFrameIsAccepted) {
  auto params = goal_params();
  params["goal"]["frame"] = kRobotBaseFrame;
  RunHarness h(type_, params);
  h.run->start();
  EXPECT_FALSE(h.result);
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  EXPECT_EQ(h.robot.pending(Kind::kMove)->goal.frame, kRobotBaseFrame);
}

TEST_F(MoveToTest, AFailedMotionStopsTheRobotThenFails) {
  RunHarness h(type_, goal_params());
  h.run->start();
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("MOTION_FAILED", "IK: unreachable")));
  EXPECT_FALSE(h.result) << "reported before the robot was stopped";
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kFailure);
  EXPECT_EQ(h.result->code, "MOTION_FAILED");
}

TEST_F(MoveToTest, AMotionTimeoutFailsWithTimeout) {
  RunHarness h(type_, goal_params());
  h.run->start();
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("TIMEOUT", "too slow")));
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "TIMEOUT");
}

TEST_F(MoveToTest, VerifyFailsWhenOffGoalStaleOrInAnotherFrame) {
  struct Case {
    std::optional<RobotSnapshot> state;
    const char* code;
  };
  for (const auto& c : {Case{at(0.52, 0.1, 0.4), "NOT_AT_GOAL"}, Case{std::nullopt, "ROBOT_STATE_STALE"},
                        Case{at(0.5, 0.1, 0.4, "world"), "NOT_VERIFIABLE"}}) {
    RunHarness h(type_, goal_params());
    h.run->start();
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
    ASSERT_TRUE(h.robot.answer_state(c.state));
    ASSERT_TRUE(h.result) << c.code;
    EXPECT_EQ(h.result->code, c.code);
    EXPECT_EQ(h.robot.stops, 0) << "nothing moves in verify: no stop";
  }
}

TEST_F(MoveToTest, NoRobotIsDeviceUnavailable) {
  testing::FakeTimers timers;
  std::optional<SkillResult> result;
  SkillRun run(type_, goal_params(), Devices{}, timers, null_logger(), {nullptr, [&](const SkillResult& r) { result = r; }});
  run.start();
  ASSERT_TRUE(result);
  EXPECT_EQ(result->code, "DEVICE_UNAVAILABLE");
}

TEST_F(MoveToTest, ShutdownWhileMovingStopsTheRobotAndIsStoppedOnlyOnceAtRest) {
  RunHarness h(type_, goal_params());
  h.run->start();
  h.run->shutdown("parallel failed");
  EXPECT_EQ(h.robot.stops, 1);
  EXPECT_EQ(h.robot.cancels, 1) << "the move's completion is no longer awaited";
  EXPECT_FALSE(h.result);
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success("at rest")));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kStopped);
}

TEST_F(MoveToTest, ShutdownWhileMovingWithAStopThatTimesOutIsSafeStopFailed) {
  RunHarness h(type_, goal_params());
  h.run->start();
  h.run->shutdown("test");
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::failure("TIMEOUT", "no rest within 3 s")));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kFailure);
  EXPECT_EQ(h.result->code, "SAFE_STOP_FAILED");
}

TEST_F(MoveToTest, ShutdownWhileVerifyingIsStoppedAtOnce) {
  RunHarness h(type_, goal_params());
  h.run->start();
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  h.run->shutdown("test");
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kStopped);
  EXPECT_FALSE(h.robot.answer_state(at(0.5, 0.1, 0.4))) << "the state wait was not cancelled";
}

TEST_F(MoveToTest, EveryStatesSafeStopReachesSafety) {
  // Each state's shutdown transition, run directly (plan is synchronous, so a SHUTDOWN never finds the
  // FSM resting in it): the safe stop must report safe, after the robot confirmed where one is needed.
  RunHarness h(type_, goal_params());
  h.run->start();
  const Skill& skill = *h.run->skill();
  EXPECT_EQ(skill.state_names(), (std::vector<std::string>{"plan", "move", "verify"}));
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_robot_stop(h));
  EXPECT_EQ(h.robot.stops, 1) << "only move commands the robot";
}

TEST(MoveToPlan, RefusesNonFiniteAndFarGoals) {
  PoseParam goal;
  goal.frame = kRobotBaseFrame;
  goal.pose.translation() = Eigen::Vector3d(0.3, 0.4, 0.0);  // 0.5 m
  EXPECT_FALSE(plan_cartesian_goal(goal, 0.5).has_value());
  EXPECT_TRUE(plan_cartesian_goal(goal, 0.49).has_value());
  goal.pose.translation().x() = std::nan("");
  EXPECT_TRUE(plan_cartesian_goal(goal, 10.0).has_value());
}

}  // namespace
}  // namespace rigger::skill_executor

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

// A PAUSE mid-motion stops the arm where it is (the motion forgotten, its timeout with it); RESUME
// commands the same goal again from there, with timeout_s afresh, and the run ends as usual.
TEST(MoveToPause, PauseStopsTheArmAndResumeMovesOnToTheSameGoal) {
  EXPECT_TRUE(MoveToSkill::describe().pausable);
  SkillType type{MoveToSkill::describe(), [] { return std::make_unique<MoveToSkill>(); }};
  RunHarness h(type, goal_params(0.5, 0.1, 0.4));
  h.run->start();
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  EXPECT_TRUE(h.run->pause(true));
  EXPECT_EQ(h.robot.pending(Kind::kMove), nullptr) << "the motion is still awaited while paused";
  EXPECT_EQ(h.robot.stops, 1);
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success("at rest")));
  EXPECT_FALSE(h.result);
  EXPECT_TRUE(h.run->pause(false));
  EXPECT_EQ(h.robot.moves, 2);
  auto* again = h.robot.pending(Kind::kMove);
  ASSERT_NE(again, nullptr);
  EXPECT_NEAR(again->goal.pose_frame_tool.translation().x(), 0.5, 1e-12);
  EXPECT_EQ(again->timeout, 10s);
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  ASSERT_TRUE(h.robot.answer_state(at(0.5, 0.1, 0.4)));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(h.robot.stops, 1);
}

TEST(MoveToPause, AnArmThatDoesNotStopFailsTheRunHoldFailed) {
  SkillType type{MoveToSkill::describe(), [] { return std::make_unique<MoveToSkill>(); }};
  RunHarness h(type, goal_params());
  h.run->start();
  EXPECT_TRUE(h.run->pause(true));
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::failure("TIMEOUT", "still moving")));
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));  // the safe stop after the failure
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "HOLD_FAILED");
}

}  // namespace
}  // namespace rigger::skill_executor
