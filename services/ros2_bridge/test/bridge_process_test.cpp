// The bridge as a real process with the shipped configuration, the test on both sides of it.
// Safe stop: the bridge obeys the robot's software safe stop (rigger/safety/stop), as every other device
// does; the test writes rigger's twist stream and reads what MoveIt Servo would get on the ROS 2 side. A
// stop sends a zero twist at once and drops the stream while it is in force, even though the stream goes
// on; its reset lets the stream through again.
// Camera: the test plays a ROS 2 camera driver writing rgb8 sensor_msgs/Image; rigger/camera/image carries
// them as mono8 with the driver's stamp, and a stale image does not cross.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

/// The bridge with the shipped configuration (deploy/config/ros2_bridge.json), READY.
bool start_shipped_bridge(Cell& cell) {
  cell.start("ros2_bridge", "ros2_bridge",
             {"--id", "ros2_bridge", "--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json"});
  return cell.wait_ready({"ros2_bridge"}, 10s);
}

struct Seen {
  double linear_x = 0.0;
  std::chrono::steady_clock::time_point at;
};

TEST(Ros2BridgeSafeStopTest, AStopSendsAZeroTwistAndHoldsTheStreamUntilItsReset) {
  Cell cell;
  ASSERT_TRUE(start_shipped_bridge(cell)) << cell.logs();
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

TEST(Ros2BridgeImageTest, ARos2CameraImageArrivesAsGreyWithItsStampAndAStaleOneDoesNot) {
  Cell cell;
  ASSERT_TRUE(start_shipped_bridge(cell)) << cell.logs();
  dds::Writer<sensor_msgs_msg_dds__Image_> camera(cell.participant(), "rt/camera/image_raw", ros2::qos::sensor_data());
  dds::Reader<rigger_vision_Image> images(cell.participant(), protocol::vision::kCameraImage);
  ASSERT_TRUE(camera.wait_for_readers(1, 5s) && images.wait_for_writers(1, 5s));
  struct Got {
    std::uint32_t width, height, step;
    std::string encoding;
    std::vector<std::uint8_t> data;
    rigger_geometry_Time stamp;
  };
  std::vector<Got> got;
  cell.loop().on_data(images, [&] {
    images.take([&](const rigger_vision_Image& i, const dds_sample_info_t&) {
      got.push_back({i.width, i.height, i.step, dds::to_string(i.encoding),
                     std::vector<std::uint8_t>(i.data._buffer, i.data._buffer + i.data._length), i.header.stamp});
    });
  });
  // 64 × 48 rgb8, a step of 200 (8 padding bytes a row); the pixel at (x, y) has R = 4x, G = 5y, B = 100.
  const std::uint32_t w = 64, h = 48, step = 200;
  std::vector<std::uint8_t> rgb(std::size_t{step} * h, 0);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      std::uint8_t* p = &rgb[std::size_t{y} * step + x * 3];
      p[0] = static_cast<std::uint8_t>(4 * x);
      p[1] = static_cast<std::uint8_t>(5 * y);
      p[2] = 100;
    }
  const auto send = [&](std::chrono::system_clock::time_point stamp) {
    sensor_msgs_msg_dds__Image_ img{};
    rigger_geometry_Header header{dds::to_wire(stamp), const_cast<char*>("camera_optical")};
    img.header_ = ros2::to_ros2(header);
    img.height_ = h;
    img.width_ = w;
    img.encoding_ = const_cast<char*>("rgb8");
    img.step_ = step;
    img.data_._buffer = rgb.data();
    img.data_._length = img.data_._maximum = static_cast<std::uint32_t>(rgb.size());
    img.data_._release = false;
    return camera.write(img);
  };
  // Best effort, as cameras publish: until discovery has settled on both sides a sample may be lost, so the
  // driver keeps publishing, every 50 ms a stale image (1 s old, the shipped limit is 0.2 s) and a fresh one.
  // Only fresh ones may cross; the bridge's log must show it dropped stale ones.
  std::vector<rigger_geometry_Time> fresh_stamps;
  cell.loop().every(50ms, [&] {
    send(std::chrono::system_clock::now() - 1s);
    const auto now = std::chrono::system_clock::now();
    fresh_stamps.push_back(dds::to_wire(now));
    send(now);
  });
  const auto bridge_dropped_stale = [&] {
    return cell.process("ros2_bridge").log().find("dropped image reason=stale") != std::string::npos;
  };
  ASSERT_TRUE(cell.wait_until([&] { return got.size() >= 3 && bridge_dropped_stale(); }, 10s)) << cell.logs();
  for (const Got& g : got) {
    const bool sent_fresh = std::any_of(fresh_stamps.begin(), fresh_stamps.end(), [&](const rigger_geometry_Time& t) {
      return t.sec == g.stamp.sec && t.nanosec == g.stamp.nanosec;
    });
    EXPECT_TRUE(sent_fresh) << "an image crossed that was not one of the fresh ones (the stale ones are 1 s old)";
  }
  const Got& g = got[0];
  EXPECT_EQ(g.encoding, "mono8");
  EXPECT_EQ(g.width, w);
  EXPECT_EQ(g.height, h);
  EXPECT_EQ(g.step, w);
  ASSERT_EQ(g.data.size(), std::size_t{w} * h);
  for (const auto& [x, y] : {std::pair<std::uint32_t, std::uint32_t>{0, 0}, {10, 20}, {63, 47}}) {
    const unsigned expected = (299u * 4 * x + 587u * 5 * y + 114u * 100 + 500u) / 1000u;
    EXPECT_EQ(g.data[std::size_t{y} * w + x], expected) << "pixel " << x << "," << y;
  }
  cell.stop_all();
}

}  // namespace
}  // namespace rigger::testing
