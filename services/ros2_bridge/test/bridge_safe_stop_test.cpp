// The bridge obeys the robot's software safe stop (rigger/safety/stop), as every other device does: the
// bridge runs as a real process with the shipped configuration; the test writes rigger's twist stream and
// reads what MoveIt Servo would get on the ROS 2 side. A stop sends a zero twist at once and drops the
// stream while it is in force, even though the stream goes on; its reset lets the stream through again.
#include <gtest/gtest.h>

#include <optional>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

struct Seen {
  double linear_x = 0.0;
  std::chrono::steady_clock::time_point at;
};

TEST(Ros2BridgeSafeStopTest, AStopSendsAZeroTwistAndHoldsTheStreamUntilItsReset) {
  Cell cell;
  cell.start("ros2_bridge", "ros2_bridge",
             {"--id", "ros2_bridge", "--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json"});
  ASSERT_TRUE(cell.wait_ready({"ros2_bridge"}, 10s)) << cell.logs();
  dds::Writer<rigger_sensing_TwistCommand> commands(cell.participant(), protocol::robot::kCmdTwist);
  dds::Reader<geometry_msgs_msg_dds__TwistStamped_> servo(cell.participant(), "rt/servo_node/delta_twist_cmds",
                                                          ros2::qos::reliable_default());
  safety::SafeStopWriter stops(cell.participant());
  ASSERT_TRUE(commands.wait_for_readers(1, 5s) && servo.wait_for_writers(1, 5s) &&
              stops.writer().wait_for_readers(1, 5s));
  std::vector<Seen> seen;
  cell.loop().on_data(servo, [&] {
    servo.take([&](const geometry_msgs_msg_dds__TwistStamped_& t, const dds_sample_info_t&) {
      seen.push_back({ros2::to_rigger(t.twist_).linear.x, std::chrono::steady_clock::now()});
    });
  });
  // rigger's stream, as admittance_control sends it: 50 Hz, fresh stamps, 0.1 m/s along x.
  std::uint64_t seq = 0;
  cell.loop().every(20ms, [&] {
    rigger_sensing_TwistCommand c{};
    c.header.stamp = dds::wire_now();
    c.header.frame_id = const_cast<char*>("base_link");
    c.seq = ++seq;
    c.twist.linear.x = 0.1;
    c.timeout_s = 0.1;
    c.source = const_cast<char*>("test");
    commands.write(c);
  });
  const auto moving = [&] { return !seen.empty() && seen.back().linear_x > 0.09; };
  ASSERT_TRUE(cell.wait_until(moving, 5s)) << "the stream is not forwarded";

  ASSERT_EQ(stops.command("robot", true, "test", "stop the arm"), DDS_RETCODE_OK);
  const auto stopped_at = std::chrono::steady_clock::now();
  const std::size_t before = seen.size();
  ASSERT_TRUE(cell.wait_until([&] { return seen.size() > before && seen.back().linear_x == 0.0; }, 2s))
      << "no zero twist after the stop";
  const double zero_ms = std::chrono::duration<double, std::milli>(seen.back().at - stopped_at).count();
  std::printf("safe stop -> zero twist on the ROS 2 side after %.1f ms\n", zero_ms);
  // The stream goes on for a second: nothing but zeros reaches the driver.
  const std::size_t after_zero = seen.size();
  cell.wait_until([] { return false; }, 1s);
  for (std::size_t i = after_zero; i < seen.size(); ++i) EXPECT_EQ(seen[i].linear_x, 0.0) << "forwarded while stopped";
  EXPECT_NE(cell.process("ros2_bridge").log().find("SAFE_STOP robot by=test"), std::string::npos);

  ASSERT_EQ(stops.command("robot", false, "test", "clear"), DDS_RETCODE_OK);
  EXPECT_TRUE(cell.wait_until(moving, 2s)) << "the stream is not forwarded after the reset";
  cell.stop_all();
}

}  // namespace
}  // namespace rigger::testing
