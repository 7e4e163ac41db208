// Nudge's FSM on the SDK's fake devices: out and back, a refused motion, and a shutdown mid-motion.
#include <gtest/gtest.h>

#include "nudge.hpp"
#include "rigger/skill_sdk/testing/run_harness.hpp"

namespace {

namespace sdk = rigger::skill_sdk;
using sdk::testing::FakeRobot;
using sdk::testing::RunHarness;
using Kind = FakeRobot::Op::Kind;

const sdk::SkillType kNudge{example::NudgeSkill::describe(), [] { return std::make_unique<example::NudgeSkill>(); }};

sdk::RobotSnapshot at(const Eigen::Vector3d& position) {
  sdk::RobotSnapshot s;
  s.frame = "robot";
  s.tool_pose.translation() = position;
  return s;
}

TEST(Nudge, MovesByTheOffsetAndBack) {
  RunHarness h(kNudge, {{"dz_m", 0.05}, {"dx_m", -0.02}});
  h.run->start();
  const Eigen::Vector3d start(0.5, 0.1, 0.4);
  ASSERT_TRUE(h.robot.answer_state(at(start)));
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  const Eigen::Vector3d nudged = h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation();
  EXPECT_TRUE(nudged.isApprox(Eigen::Vector3d(0.48, 0.1, 0.45)));
  ASSERT_TRUE(h.robot.complete(Kind::kMove, sdk::OpResult::success()));
  ASSERT_TRUE(h.robot.answer_state(at(nudged)));
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  EXPECT_TRUE(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.translation().isApprox(start));
  ASSERT_TRUE(h.robot.complete(Kind::kMove, sdk::OpResult::success()));
  ASSERT_TRUE(h.robot.answer_state(at(start)));
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 2);
}

TEST(Nudge, AToolShortOfItsGoalFailsNotReached) {
  RunHarness h(kNudge, {{"return", false}});
  h.run->start();
  ASSERT_TRUE(h.robot.answer_state(at({0.5, 0.0, 0.4})));
  ASSERT_TRUE(h.robot.complete(Kind::kMove, sdk::OpResult::success()));
  ASSERT_TRUE(h.robot.answer_state(at({0.5, 0.0, 0.43})));  // 20 mm short of dz 0.05
  EXPECT_TRUE(h.failed_with("NOT_REACHED")) << h.describe_result();
}

TEST(Nudge, AnOffsetOutOfRangeIsRefusedBeforeAnythingMoves) {
  RunHarness h(kNudge, {{"dz_m", 0.5}});
  h.run->start();
  EXPECT_TRUE(h.failed_with("BAD_PARAMS")) << h.describe_result();
  EXPECT_EQ(h.robot.moves, 0);
}

TEST(Nudge, AShutdownMidMotionStopsTheRobot) {
  RunHarness h(kNudge, nlohmann::json::object());
  h.run->start();
  ASSERT_TRUE(h.robot.answer_state(at({0.5, 0.0, 0.4})));
  h.run->shutdown("test");
  ASSERT_TRUE(h.robot.complete(Kind::kStop, sdk::OpResult::success()));
  EXPECT_TRUE(h.stopped()) << h.describe_result();
}

TEST(Nudge, WithoutARobotItFailsDeviceUnavailable) {
  RunHarness h(kNudge, nlohmann::json::object(), [](sdk::Devices& d) { d.robot = nullptr; });
  h.run->start();
  EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << h.describe_result();
}

}  // namespace
