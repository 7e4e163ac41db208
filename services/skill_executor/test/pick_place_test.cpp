// Pick and Place on fakes (the simulated cell has no object within the robot's payload): success paths
// with what is commanded, each failure code, bad params, and a shutdown from every state.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "tool_poses.hpp"
#include "skills/pick_place.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::FakeGripper;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

// A part on a table in front of the robot, grasped from above (tool z down).
const Eigen::Isometry3d kGrasp = tool_down(0.60, 0.10, 0.05);

nlohmann::json pick_params() {
  return {{"object", "part"}, {"grasp", "part/grasp_top"}};
}
nlohmann::json place_params(nlohmann::json pose = {{"position_m", {0.5, -0.2, 0.10}}, {"rpy_deg", {180.0, 0.0, 0.0}}}) {
  return {{"object", "part"}, {"pose", std::move(pose)}};
}

/// Completes what the current state waits for, as on the success path (Pick and Place share state
/// names where they do the same).
void step(RunHarness& h, bool holding_at_start) {
  const std::string s = h.state();
  if (const auto* update = h.world.pending_update()) {  // Place's end: the part moved unobserved
    EXPECT_EQ(update->entity, "part");
    EXPECT_FALSE(update->localized);
    ASSERT_TRUE(h.world.answer_update(OpResult::success()));
  } else if (s == "check") {
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(holding_at_start, holding_at_start)), 1);
  } else if (s == "resolve") {
    ASSERT_NE(h.resolver.oldest(), nullptr);
    EXPECT_EQ(h.resolver.oldest()->frame, kRobotBaseFrame);
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), kGrasp));
  } else if (s == "move_approach" || s == "descend" || s == "retreat") {
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  } else if (s == "grip" || s == "release") {
    ASSERT_TRUE(h.gripper.confirm());
  } else if (s == "await_hold" || s == "verify") {
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 1);
  } else if (s == "confirm_released") {
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
  } else {
    FAIL() << "no step for state " << s;
  }
}

void start(RunHarness& h) {
  h.run->start();
  while (!h.run->skill() && !h.result && h.resolver.pending() > 0) h.resolver.answer(OpResult::success());
}

void drive_to(RunHarness& h, const std::string& target, bool holding_at_start) {
  run_steps::drive_to(h, target, [holding_at_start](RunHarness& r) { step(r, holding_at_start); });
}

void run_to_end(RunHarness& h, bool holding_at_start) {
  run_steps::run_to_end(h, [holding_at_start](RunHarness& r) { step(r, holding_at_start); });
}

/// Shutdown in each of `states` of a run of `type` (Pick: nothing held at the start; Place: the part held).
void expect_shutdown_in_each_state(const SkillType& type, const nlohmann::json& params,
                                   const std::vector<std::string>& states, bool holding_at_start) {
  run_steps::expect_shutdown_in_each_state(type, params, states, {"move_approach", "descend", "retreat"},
                                           [holding_at_start](RunHarness& h, const std::string& state) {
                                             start(h);
                                             drive_to(h, state, holding_at_start);
                                           });
}

class PickTest : public ::testing::Test {
 protected:
  SkillType type_{PickSkill::describe(), [] { return std::make_unique<PickSkill>(); }};
};

// PAUSE during the descent: the arm stops, neither the motion's nor the run's timeout_s runs out while
// paused; RESUME commands the same grasp goal again and the pick completes.
TEST_F(PickTest, APauseStopsTheDescentAndResumeDescendsToTheSameGrasp) {
  EXPECT_TRUE(PickSkill::describe().pausable);
  RunHarness h(type_, pick_params());
  start(h);
  drive_to(h, "descend", false);
  const Eigen::Vector3d goal = h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation();
  ASSERT_TRUE(h.run->pause(true));
  EXPECT_EQ(h.robot.pending(Kind::kMove), nullptr);
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  h.timers.advance(600s);  // far past timeout_s (default 60 s)
  ASSERT_FALSE(h.result) << h.describe_result();
  EXPECT_EQ(h.robot.stops, 1) << "a timeout ran out while paused (its safe stop stopped the arm again)";
  ASSERT_TRUE(h.run->pause(false));
  ASSERT_EQ(h.state(), "descend");
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  EXPECT_TRUE(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().isApprox(goal));
  run_to_end(h, false);
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kSuccess) << h.describe_result();
  // The run's timeout counts again from the resume.
  RunHarness late(type_, pick_params());
  start(late);
  drive_to(late, "descend", false);
  ASSERT_TRUE(late.run->pause(true));
  ASSERT_TRUE(late.robot.complete(Kind::kStop, OpResult::success()));
  ASSERT_TRUE(late.run->pause(false));
  late.timers.advance(61s);
  ASSERT_TRUE(late.robot.complete(Kind::kStop, OpResult::success()));  // the safe stop before the report
  ASSERT_TRUE(late.result);
  EXPECT_EQ(late.result->code, "TIMEOUT");
}

TEST_F(PickTest, ApproachesDescendsGripsAndRetreats) {
  RunHarness h(type_, pick_params());
  start(h);
  drive_to(h, "move_approach", false);
  auto* move = h.robot.pending(Kind::kMove);
  ASSERT_NE(move, nullptr);
  // approach_m 0.10 back along the tool -z = 0.10 m up.
  EXPECT_NEAR(move->goal.pose_frame_tool.translation().z(), 0.15, 1e-12);
  EXPECT_NEAR(move->goal.speed_scale, 0.2, 1e-12);
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  move = h.robot.pending(Kind::kMove);
  ASSERT_NE(move, nullptr);
  EXPECT_TRUE(move->goal.pose_frame_tool.isApprox(kGrasp, 1e-12));
  EXPECT_NEAR(move->goal.speed_scale, 0.05 / kRobotMaxToolSpeedMps, 1e-12);
  EXPECT_TRUE(h.gripper.commanded.empty()) << "energized only at the grasp";
  drive_to(h, "retreat", false);
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{true});
  EXPECT_NEAR(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().z(), 0.15, 1e-12);
  run_to_end(h, false);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 3);
  EXPECT_EQ(h.robot.stops, 0);
}

TEST_F(PickTest, FailureCodes) {
  {  // already holding
    RunHarness h(type_, pick_params());
    start(h);
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 1);
    EXPECT_TRUE(h.failed_with("GRIPPER_OCCUPIED")) << h.describe_result();
  }
  for (const char* code : {"UNKNOWN_FEATURE", "WORLD_UNREACHABLE"}) {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "resolve", false);
    ASSERT_TRUE(h.resolver.answer(OpResult::failure(code, "test")));
    EXPECT_TRUE(h.failed_with(code)) << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "resolve", false);
    h.resolver.localized = false;
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), kGrasp));
    EXPECT_TRUE(h.failed_with("NOT_LOCALIZED")) << h.describe_result();
  }
  {  // out of reach
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "resolve", false);
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), tool_down(1.3, 0.0, 0.05)));
    EXPECT_TRUE(h.failed_with("PLAN_FAILED")) << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
  for (const char* state : {"move_approach", "descend", "retreat"}) {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, state, false);
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("MOTION_FAILED", "x")));
    EXPECT_FALSE(h.result);
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("MOTION_FAILED")) << state << ": " << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "grip", false);
    ASSERT_TRUE(h.gripper.confirm(OpResult::failure("TIMEOUT", "x")));
    EXPECT_TRUE(h.failed_with("GRIPPER_TIMEOUT")) << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "await_hold", false);
    ASSERT_TRUE(h.gripper.time_out_wait());
    EXPECT_TRUE(h.failed_with("GRASP_FAILED")) << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params());
    start(h);
    drive_to(h, "verify", false);
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, false)), 1);
    EXPECT_TRUE(h.failed_with("GRASP_LOST")) << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params());
    start(h);
    ASSERT_TRUE(h.gripper.time_out_wait());
    EXPECT_TRUE(h.failed_with("GRIPPER_STATE_STALE")) << h.describe_result();
  }
  {
    RunHarness h(type_, {{"object", "part"}, {"grasp", "part/grasp_top"}, {"timeout_s", 2.0}});
    start(h);
    drive_to(h, "descend", false);
    h.timers.advance(2s);
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("TIMEOUT")) << h.describe_result();
  }
  {
    RunHarness h(type_, pick_params(), [](Devices& d) { d.gripper = nullptr; });
    start(h);
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << h.describe_result();
  }
  {
    RunHarness h(type_, {{"grasp", "part/grasp_top"}, {"approach_m", 2.0}});
    h.run->start();
    EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << h.describe_result();
    EXPECT_NE(h.result->message.find("/params/object"), std::string::npos);
    EXPECT_NE(h.result->message.find("/params/approach_m"), std::string::npos);
  }
}

TEST_F(PickTest, ShutdownInEveryStateReachesItsSafeStop) {
  expect_shutdown_in_each_state(
      type_, pick_params(), {"check", "resolve", "move_approach", "descend", "grip", "await_hold", "retreat", "verify"},
      false);
}

class PlaceTest : public ::testing::Test {
 protected:
  SkillType type_{PlaceSkill::describe(), [] { return std::make_unique<PlaceSkill>(); }};
};

TEST_F(PlaceTest, ApproachesDescendsReleasesAndRetreats) {
  RunHarness h(type_, place_params());
  start(h);
  drive_to(h, "move_approach", true);
  auto* move = h.robot.pending(Kind::kMove);
  ASSERT_NE(move, nullptr);
  EXPECT_NEAR(move->goal.pose_frame_tool.translation().z(), 0.20, 1e-12);  // 0.10 above the place pose
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  EXPECT_NEAR(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().z(), 0.10, 1e-12);
  drive_to(h, "retreat", true);
  EXPECT_EQ(h.gripper.commanded, std::vector<bool>{false});
  EXPECT_NEAR(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().z(), 0.20, 1e-12);
  run_to_end(h, true);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_NE(h.result->message.find("part no longer localized"), std::string::npos) << h.result->message;
  EXPECT_EQ(h.robot.moves, 3);
}

// After the release and the retreat the world model is told that the part is no longer localized (it still
// holds the pose the part was picked at), and only then does Place succeed; a world model that cannot be
// told fails the run with WORLD_UPDATE_FAILED naming the part, so that nothing picks it where it was.
TEST_F(PlaceTest, ThePlacedObjectIsNoLongerLocalizedInTheWorldModel) {
  for (const bool told : {true, false}) {
    testing::FakeWorldAccess world;
    RunHarness h(type_, place_params(), [&](Devices& d) { d.world_access = &world; });
    start(h);
    drive_to(h, "retreat", true);
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
    ASSERT_FALSE(h.result) << "Place ended before the world model was told: " << h.describe_result();
    const auto* update = world.pending_update();
    ASSERT_NE(update, nullptr);
    EXPECT_EQ(update->entity, "part");
    EXPECT_FALSE(update->localized);
    ASSERT_TRUE(world.answer_update(told ? OpResult::success("ACCEPTED")
                                         : OpResult::failure("WORLD_UNREACHABLE", "no reply within 2000 ms")));
    if (told) {
      EXPECT_TRUE(h.succeeded()) << h.describe_result();
      EXPECT_NE(h.result->message.find("part no longer localized"), std::string::npos) << h.result->message;
    } else {
      // As every failure: the robot's stop confirmed first (it already stands still).
      ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
      EXPECT_TRUE(h.failed_with("WORLD_UPDATE_FAILED")) << h.describe_result();
      EXPECT_NE(h.result->message.find("placed part, but the world model could not be told"), std::string::npos)
          << h.result->message;
    }
  }
}

TEST_F(PlaceTest, APoseRelativeToAFeatureIsResolvedInTheRobotFrame) {
  RunHarness h(
      type_,
      place_params({{"position_m", {0.0, 0.0, -0.02}}, {"rpy_deg", {0.0, 0.0, 0.0}}, {"frame", "part/grasp_top"}}));
  start(h);
  drive_to(h, "resolve", true);
  EXPECT_EQ(h.resolver.oldest()->ref, "part/grasp_top");
  ASSERT_TRUE(h.resolver.answer(OpResult::success(), kGrasp));
  ASSERT_EQ(h.state(), "move_approach");
  // 0.02 m along the feature's -z (tool down: up) plus the 0.10 m approach.
  EXPECT_NEAR(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().z(), 0.05 + 0.02 + 0.10, 1e-12);
}

TEST_F(PlaceTest, FailureCodes) {
  {
    RunHarness h(type_, place_params());
    start(h);
    ASSERT_EQ(h.gripper.publish(FakeGripper::state(false, false)), 1);
    EXPECT_TRUE(h.failed_with("NOT_HOLDING")) << h.describe_result();
  }
  {
    RunHarness h(
        type_, place_params({{"position_m", {0.5, 0.0, 0.1}}, {"rpy_deg", {180.0, 0.0, 0.0}}, {"frame", "world"}}));
    start(h);
    EXPECT_TRUE(h.failed_with("PLAN_FAILED")) << h.describe_result();
    EXPECT_NE(h.result->message.find("'world'"), std::string::npos);
  }
  {
    RunHarness h(
        type_, place_params({{"position_m", {0.0, 0.0, 0.0}}, {"rpy_deg", {0.0, 0.0, 0.0}}, {"frame", "fixture/top"}}));
    start(h);
    drive_to(h, "resolve", true);
    ASSERT_TRUE(h.resolver.answer(OpResult::failure("UNKNOWN_FEATURE", "no fixture")));
    EXPECT_TRUE(h.failed_with("UNKNOWN_FEATURE")) << h.describe_result();
  }
  for (const char* state : {"move_approach", "descend", "retreat"}) {
    RunHarness h(type_, place_params());
    start(h);
    drive_to(h, state, true);
    ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::failure("MOTION_FAILED", "x")));
    ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    EXPECT_TRUE(h.failed_with("MOTION_FAILED")) << state << ": " << h.describe_result();
  }
  {
    RunHarness h(type_, place_params());
    start(h);
    drive_to(h, "confirm_released", true);
    ASSERT_TRUE(h.gripper.time_out_wait());
    EXPECT_TRUE(h.failed_with("RELEASE_FAILED")) << h.describe_result();
  }
  {
    RunHarness h(type_, place_params());
    start(h);
    drive_to(h, "release", true);
    ASSERT_TRUE(h.gripper.confirm(OpResult::failure("TIMEOUT", "x")));
    EXPECT_TRUE(h.failed_with("GRIPPER_TIMEOUT")) << h.describe_result();
  }
  {
    RunHarness h(type_, {{"object", "part"}});
    h.run->start();
    EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << h.describe_result();
    EXPECT_NE(h.result->message.find("/params/pose"), std::string::npos);
  }
}

TEST_F(PlaceTest, AnUnreachablePlacePoseIsPlanFailedWithoutMoving) {
  RunHarness h(type_, place_params({{"position_m", {2.0, 0.0, 0.1}}, {"rpy_deg", {180.0, 0.0, 0.0}}}));
  start(h);
  ASSERT_EQ(h.gripper.publish(FakeGripper::state(true, true)), 1);
  EXPECT_TRUE(h.failed_with("PLAN_FAILED")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
}

TEST_F(PlaceTest, ShutdownInEveryStateReachesItsSafeStop) {
  expect_shutdown_in_each_state(type_, place_params(),
                                {"check", "move_approach", "descend", "release", "confirm_released", "retreat"}, true);
  // resolve (synchronous for a robot-frame pose) and every other state, through find_state.
  RunHarness h(type_, place_params());
  start(h);
  run_steps::expect_every_safe_stop_safe(h, run_steps::confirm_robot_stop(h));
  EXPECT_EQ(h.robot.stops, 3);
}

}  // namespace
}  // namespace rigger::skill_executor
