// The DDS primitives against a fake driver in the same process: gripper confirmation by seq, motion
// completion by motion_id, timeouts, and the topic-condition wait.
#include <gtest/gtest.h>

#include "dds_devices.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/testing/domain.hpp"
#include "world_resolver.hpp"

namespace rigger::skill_sdk {
namespace {

using namespace std::chrono_literals;

class DdsDevicesTest : public ::testing::Test {
 protected:
  testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
};

TEST_F(DdsDevicesTest, GripperConfirmsOnlyTheStateOfItsOwnCommand) {
  DdsGripper gripper(participant_, loop_, null_logger(), "exec");
  dds::Reader<rigger_robot_GripperCommand> cmds(participant_, protocol::robot::kGripperCmd);
  dds::Writer<rigger_robot_GripperState> state(participant_, protocol::robot::kGripperState);
  std::vector<rigger_robot_GripperCommand> received;
  loop_.on_data(cmds, [&] { cmds.take([&](const rigger_robot_GripperCommand& c, const dds_sample_info_t&) { received.push_back(c); }); });
  std::optional<OpResult> result;
  gripper.set_energized(true, 5s, [&](const OpResult& r) { result = r; });
  ASSERT_TRUE(loop_.run_until([&] { return !received.empty(); }, 5s));
  EXPECT_TRUE(received[0].energize);
  rigger_robot_GripperState s{};
  s.energized = true;
  s.last_command_seq = received[0].seq - 1;  // an older command's state: not a confirmation
  state.write(s);
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(result);
  s.last_command_seq = received[0].seq;
  state.write(s);
  ASSERT_TRUE(loop_.run_until([&] { return result.has_value(); }, 5s));
  EXPECT_TRUE(result->ok);
}

TEST_F(DdsDevicesTest, GripperTimesOutWithoutAnAnswer) {
  DdsGripper gripper(participant_, loop_, null_logger(), "exec");
  std::optional<OpResult> result;
  gripper.set_energized(false, 50ms, [&](const OpResult& r) { result = r; });
  ASSERT_TRUE(loop_.run_until([&] { return result.has_value(); }, 5s));
  EXPECT_FALSE(result->ok);
  EXPECT_EQ(result->code, "TIMEOUT");
}

TEST_F(DdsDevicesTest, GripperWaitStateEndsOnTheFirstMatchingSampleOrTimesOut) {
  DdsGripper gripper(participant_, loop_, null_logger(), "exec");
  dds::Writer<rigger_robot_GripperState> state(participant_, protocol::robot::kGripperState);
  ASSERT_TRUE(state.wait_for_readers(1, 5s));
  std::optional<std::optional<GripperSnapshot>> holding, timed_out;
  gripper.wait_state([](const GripperSnapshot& g) { return g.holding; }, 5s,
                     [&](std::optional<GripperSnapshot> g) { holding = g; });
  gripper.wait_state([](const GripperSnapshot& g) { return g.holding_force_n > 5000.0; }, 200ms,
                     [&](std::optional<GripperSnapshot> g) { timed_out = g; });
  rigger_robot_GripperState s{};
  s.energized = true;
  s.contact = true;
  state.write(s);  // energized, not holding: no answer to the first wait
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(holding);
  s.holding = true;
  s.holding_force_n = 1200.0;
  s.header.stamp = dds::wire_now();
  state.write(s);
  ASSERT_TRUE(loop_.run_until([&] { return holding && timed_out; }, 5s));
  ASSERT_TRUE(holding->has_value());
  EXPECT_TRUE((*holding)->holding);
  EXPECT_TRUE((*holding)->contact);
  EXPECT_DOUBLE_EQ((*holding)->holding_force_n, 1200.0);
  EXPECT_FALSE(timed_out->has_value());
}

TEST_F(DdsDevicesTest, RobotMoveEndsOnItsOwnMotionIdAndATimeoutStopsIt) {
  DdsRobot robot(participant_, loop_, null_logger(), "exec");
  dds::Reader<rigger_robot_MotionCommand> cmds(participant_, protocol::robot::kCmdMotion);
  dds::Writer<rigger_robot_MotionStatus> status(participant_, protocol::robot::kMotionStatus);
  std::vector<std::pair<std::string, rigger_robot_MotionKind>> received;
  loop_.on_data(cmds, [&] {
    cmds.take([&](const rigger_robot_MotionCommand& c, const dds_sample_info_t&) {
      received.emplace_back(dds::to_string(c.motion_id), c.kind);
    });
  });
  auto answer = [&](const std::string& id, rigger_robot_MotionState st) {
    rigger_robot_MotionStatus s{};
    s.motion_id = dds::wire_string(id);
    s.state = st;
    status.write(s);
  };
  std::optional<OpResult> first, second;
  robot.move(MotionGoal{}, 5s, [&](const OpResult& r) { first = r; });
  robot.move(MotionGoal{}, 100ms, [&](const OpResult& r) { second = r; });
  ASSERT_TRUE(loop_.run_until([&] { return received.size() == 2; }, 5s));
  EXPECT_NE(received[0].first, received[1].first);
  answer(received[0].first, rigger_robot_MOTION_EXECUTING);  // progress only
  answer(received[0].first, rigger_robot_MOTION_SUCCEEDED);
  ASSERT_TRUE(loop_.run_until([&] { return first && second; }, 5s));
  EXPECT_TRUE(first->ok);
  EXPECT_EQ(second->code, "TIMEOUT");
  // The overrun motion is stopped.
  ASSERT_TRUE(loop_.run_until([&] { return received.size() == 3; }, 5s));
  EXPECT_EQ(received[2].second, rigger_robot_MOTION_STOP);
}

TEST_F(DdsDevicesTest, NextStateWaitsForAFreshSample) {
  DdsRobot robot(participant_, loop_, null_logger(), "exec");
  dds::Writer<rigger_robot_RobotState> state(participant_, protocol::robot::kState);
  ASSERT_TRUE(state.wait_for_readers(1, 5s));
  std::optional<std::optional<RobotSnapshot>> got;
  robot.next_state(5s, [&](std::optional<RobotSnapshot> s) { got = s; });
  rigger_robot_RobotState old{};
  old.header.stamp = dds::to_wire(std::chrono::system_clock::now() - 10s);
  state.write(old);
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(got) << "an old sample answered";
  rigger_robot_RobotState fresh{};
  const std::string frame = "robot";
  fresh.header.stamp = dds::wire_now();
  fresh.header.frame_id = dds::wire_string(frame);
  fresh.tool_pose.position.x = 0.7;
  fresh.tool_pose.orientation.w = 1.0;
  state.write(fresh);
  ASSERT_TRUE(loop_.run_until([&] { return got.has_value(); }, 5s));
  ASSERT_TRUE(got->has_value());
  EXPECT_EQ((*got)->frame, "robot");
  EXPECT_NEAR((*got)->tool_pose.translation().x(), 0.7, 1e-12);
}

TEST(FeatureRef, SplitsEntityAndFeatureId) {
  EXPECT_EQ(split_feature_ref("load/grasp_top"), std::make_pair(std::string("load"), std::string("grasp_top")));
  EXPECT_EQ(split_feature_ref("target/screw_holes/h3"), std::make_pair(std::string("target"), std::string("h3")));
  EXPECT_FALSE(split_feature_ref("load"));
  EXPECT_FALSE(split_feature_ref("/x"));
  EXPECT_FALSE(split_feature_ref("load/"));
}

}  // namespace
}  // namespace rigger::skill_sdk
