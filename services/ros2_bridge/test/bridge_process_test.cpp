// The bridge as a real process with the shipped configuration, the test on both sides of it.
// Safe stop: the bridge obeys the robot's software safe stop (rigger/safety/stop), as every other device
// does; the test writes rigger's twist stream and reads what MoveIt Servo would get on the ROS 2 side. A
// stop sends a zero twist at once and drops the stream while it is in force, even though the stream goes
// on; its reset lets the stream through again.
// Camera: the test plays a ROS 2 camera driver writing rgb8 sensor_msgs/Image; rigger/camera/image carries
// them as mono8 with the driver's stamp, and a stale image does not cross.
// Joint states: the test plays joint_state_broadcaster; rigger/robot/state carries each fresh message as the
// bridge's kinematics compute it from the shipped configuration, and refused ones do not cross.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/testing/cell.hpp"

#include "bridge_config.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

/// The bridge with the shipped configuration (deploy/config/ros2_bridge.json), READY.
bool start_shipped_bridge(Cell& cell) {
  cell.start("ros2_bridge", "ros2_bridge",
             {"--id", "ros2_bridge", "--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json"});
  return cell.wait_ready({"ros2_bridge"}, 10s);
}

/// The shipped configuration's joint_states stream: the arm the bridge computes with.
ros2_bridge::JointStatesStream shipped_joint_states() {
  const Config file = Config::load(std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json");
  const ros2_bridge::BridgeConfig shipped = ros2_bridge::read_bridge_config(file);
  if (!shipped.joint_states) throw std::runtime_error("the shipped ros2_bridge.json bridges no joint_states");
  return *shipped.joint_states;
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
      got.push_back({i.width, i.height, i.step, dds::to_string(i.encoding), dds::to_vector<std::uint8_t>(i.data),
                     i.header.stamp});
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
    dds::wire_sequence(img.data_, rgb);
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

TEST(Ros2BridgeImageTest, TheDriversCameraInfoBecomesRiggersOnceAndARationalPolynomialOneDoesNot) {
  Cell cell;
  ASSERT_TRUE(start_shipped_bridge(cell)) << cell.logs();
  dds::Writer<sensor_msgs_msg_dds__CameraInfo_> driver(cell.participant(), "rt/camera/camera_info",
                                                       ros2::qos::sensor_data());
  dds::Reader<rigger_vision_CameraInfo> infos(cell.participant(), protocol::vision::kCameraInfo);
  ASSERT_TRUE(driver.wait_for_readers(1, 5s) && infos.wait_for_writers(1, 5s));
  struct Got {
    std::string model, frame;
    std::vector<double> d;
    double fx, cy;
    std::uint32_t width;
  };
  std::vector<Got> got;
  cell.loop().on_data(infos, [&] {
    infos.take([&](const rigger_vision_CameraInfo& i, const dds_sample_info_t&) {
      got.push_back({dds::to_string(i.distortion_model), dds::to_string(i.header.frame_id),
                     dds::to_vector<double>(i.d), i.k[0], i.k[5], i.width});
    });
  });
  std::vector<double> d4 = {-0.2, 0.05, 0.001, -0.001};  // k3 left out
  std::vector<double> d8 = {0.1, 0.2, 0.0, 0.0, 0.3, 0.4, 0.5, 0.6};
  const auto send = [&](const char* model, std::vector<double>& d, double fx) {
    sensor_msgs_msg_dds__CameraInfo_ info{};
    rigger_geometry_Header header{dds::to_wire(std::chrono::system_clock::now()), const_cast<char*>("camera_optical")};
    info.header_ = ros2::to_ros2(header);
    info.height_ = 720;
    info.width_ = 1280;
    info.distortion_model_ = const_cast<char*>(model);
    info.d_ = {static_cast<std::uint32_t>(d.size()), static_cast<std::uint32_t>(d.size()), d.data(), false};
    const double k[9] = {fx, 0, 639.5, 0, fx, 359.5, 0, 0, 1};
    const double p[12] = {fx, 0, 639.5, 0, 0, fx, 359.5, 0, 0, 0, 1, 0};
    std::copy(std::begin(k), std::end(k), std::begin(info.k_));
    info.r_[0] = info.r_[4] = info.r_[8] = 1.0;
    std::copy(std::begin(p), std::end(p), std::begin(info.p_));
    return driver.write(info);
  };
  // A driver repeats its info with every image (best effort: repeated until one crossed); the rigger topic
  // is state: it changes once. Then a model rigger's camera model does not have: refused, nothing written.
  const auto timer = cell.loop().every(50ms, [&] {
    send("plumb_bob", d4, 1000.0);
    send("rational_polynomial", d8, 900.0);
  });
  const auto dropped_model = [&] {
    return cell.process("ros2_bridge").log().find("dropped camera_info reason=distortion_model") != std::string::npos;
  };
  ASSERT_TRUE(cell.wait_until([&] { return !got.empty() && dropped_model(); }, 10s)) << cell.logs();
  cell.loop().cancel(timer);
  ASSERT_EQ(got.size(), 1u) << "rigger/camera/info is written when the intrinsics change, not with each image";
  EXPECT_EQ(got[0].model, "plumb_bob");
  EXPECT_EQ(got[0].d, (std::vector<double>{-0.2, 0.05, 0.001, -0.001, 0.0}));
  EXPECT_EQ(got[0].fx, 1000.0);
  EXPECT_EQ(got[0].cy, 359.5);
  EXPECT_EQ(got[0].width, 1280u);
  EXPECT_EQ(got[0].frame, "camera_optical");
  cell.stop_all();
}

void expect_same(const rigger_geometry_Pose& got, const rigger_geometry_Pose& want, const char* what) {
  const double g[7] = {got.position.x,    got.position.y,    got.position.z,   got.orientation.x,
                       got.orientation.y, got.orientation.z, got.orientation.w};
  const double w[7] = {want.position.x,    want.position.y,    want.position.z,   want.orientation.x,
                       want.orientation.y, want.orientation.z, want.orientation.w};
  for (int i = 0; i < 7; ++i) EXPECT_EQ(g[i], w[i]) << what << " pose field " << i;
}

void expect_same(const rigger_geometry_Twist& got, const rigger_geometry_Twist& want) {
  EXPECT_EQ(dds::to_domain(got), dds::to_domain(want)) << "tool twist";
}

/// The shipped bridge, READY, with the test as joint_state_broadcaster (`driver`) and reading the robot state.
class Ros2BridgeJointStatesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(start_shipped_bridge(cell)) << cell.logs();
    ASSERT_TRUE(driver.wait_for_readers(1, 5s) && states.wait_for_writers(1, 5s));
  }

  Cell cell;
  const ros2_bridge::JointStatesStream arm = shipped_joint_states();
  dds::Writer<sensor_msgs_msg_dds__JointState_> driver{cell.participant(), "rt/joint_states",
                                                       ros2::qos::system_default()};
  dds::Reader<rigger_robot_RobotState> states{cell.participant(), protocol::robot::kState};
};

TEST_F(Ros2BridgeJointStatesTest, AJointStateBecomesTheRobotStateComputedFromTheArmsKinematics) {
  struct Got {
    rigger_geometry_Time stamp;
    std::string frame, fault;
    rigger_robot_RobotMode mode;
    bool moving;
    std::uint64_t last_command_seq;
    std::vector<double> q, qd;
    rigger_geometry_Pose flange, tool;
    rigger_geometry_Twist twist;
  };
  std::vector<Got> got;
  cell.loop().on_data(states, [&] {
    states.take([&](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
      got.push_back({s.header.stamp, dds::to_string(s.header.frame_id), dds::to_string(s.fault), s.mode, s.moving,
                     s.last_command_seq, dds::to_vector<double>(s.joint_position),
                     dds::to_vector<double>(s.joint_velocity), s.flange_pose, s.tool_pose, s.tool_twist});
    });
  });
  // Message k: joint i (chain order) at 0.1 i - 0.3 + 0.01 k rad, turning at 0.05 (i + 1) rad/s, written last
  // joint first. In turn the driver writes a fresh one, one a second old, and one naming a joint the
  // configuration does not know.
  struct Sent {
    rigger_geometry_Time stamp;
    Eigen::VectorXd q, qd;
  };
  std::vector<Sent> sent;
  int k = 0;
  const auto send = [&](std::chrono::system_clock::time_point stamp, bool unknown_joint) {
    const int n = 7;
    Eigen::VectorXd q(n), qd(n);
    std::vector<std::string> names(n);
    std::vector<char*> name_ptrs(n);
    std::vector<double> position(n), velocity(n), effort(n, 1.5);
    for (int j = 0; j < n; ++j) {
      const int i = n - 1 - j;
      q[i] = 0.1 * i - 0.3 + 0.01 * k;
      qd[i] = 0.05 * (i + 1);
      names[j] = unknown_joint && i == 2 ? "joint_a3_typo" : arm.joints[static_cast<std::size_t>(i)];
      name_ptrs[j] = names[j].data();
      position[j] = q[i];
      velocity[j] = qd[i];
    }
    rigger_geometry_Header header{dds::to_wire(stamp), const_cast<char*>("")};
    ASSERT_EQ(driver.write(ros2::to_ros2_joint_state(header, name_ptrs, position, velocity, effort)), DDS_RETCODE_OK);
    if (!unknown_joint && std::chrono::system_clock::now() - stamp < 100ms) sent.push_back({header.stamp, q, qd});
  };
  // One message per tick, as joint_state_broadcaster publishes once per control cycle (system_default QoS
  // keeps the newest sample only: a burst would leave the bridge the last one).
  cell.loop().every(10ms, [&] {
    ++k;
    if (k % 3 == 0) send(std::chrono::system_clock::now(), false);
    if (k % 3 == 1) send(std::chrono::system_clock::now() - 1s, false);
    if (k % 3 == 2) send(std::chrono::system_clock::now(), true);
  });
  const auto dropped = [&](const char* reason) {
    return cell.process("ros2_bridge").log().find(std::string("dropped joint_states reason=") + reason) !=
           std::string::npos;
  };
  ASSERT_TRUE(cell.wait_until([&] { return got.size() >= 20 && dropped("stale") && dropped("unknown_joint"); }, 10s))
      << cell.logs();
  EXPECT_NE(cell.process("ros2_bridge").log().find("joint 'joint_a3_typo' is neither one of the arm's joints"),
            std::string::npos);
  for (const Got& g : got) {
    const auto it = std::find_if(sent.begin(), sent.end(), [&](const Sent& s) {
      return s.stamp.sec == g.stamp.sec && s.stamp.nanosec == g.stamp.nanosec;
    });
    ASSERT_NE(it, sent.end()) << "a robot state crossed that was not one of the fresh, valid joint states";
    const ros2_bridge::ArmState expected = arm.kinematics->evaluate(it->q, it->qd, arm.pose_flange_tool);
    EXPECT_EQ(g.frame, "robot");
    EXPECT_EQ(g.fault, "");
    EXPECT_EQ(g.mode, rigger_robot_ROBOT_IDLE);
    EXPECT_TRUE(g.moving);
    EXPECT_EQ(g.last_command_seq, 0u);
    EXPECT_EQ(g.q, std::vector<double>(it->q.data(), it->q.data() + 7)) << "chain order, exactly as sent";
    EXPECT_EQ(g.qd, std::vector<double>(it->qd.data(), it->qd.data() + 7));
    // The same library computed both: equal to the bit, on the wire (poses as position and quaternion).
    dds::Vector6d twist;
    twist << expected.tool_linear_mps, expected.tool_angular_radps;
    expect_same(g.flange, dds::to_wire(expected.pose_base_flange), "flange");
    expect_same(g.tool, dds::to_wire(expected.pose_base_tool), "tool");
    expect_same(g.twist, dds::to_wire_twist(twist));
  }
  std::printf("%zu robot states from %zu fresh joint states (and as many stale and unknown-joint ones)\n", got.size(),
              sent.size());
  EXPECT_GE(got.size() + 2, sent.size()) << "fresh joint states lost on the way (at most the last two in flight)";
  cell.stop_all();
}

// What JointState does not say, the bridge says from what it knows itself: while it holds a twist command it
// forwarded to MoveIt Servo the robot state's mode is ROBOT_VELOCITY with that command's seq, and once the
// command's timeout has passed (the bridge then sends Servo a zero) it is ROBOT_IDLE again.
TEST_F(Ros2BridgeJointStatesTest, ModeIsVelocityWhileTheBridgeHoldsAServoCommand) {
  dds::Writer<rigger_sensing_TwistCommand> commands(cell.participant(), protocol::robot::kCmdTwist);
  dds::Reader<geometry_msgs_msg_dds__TwistStamped_> servo(cell.participant(), "rt/servo_node/delta_twist_cmds",
                                                          ros2::qos::reliable_default());
  ASSERT_TRUE(commands.wait_for_readers(1, 5s) && servo.wait_for_writers(1, 5s));
  std::vector<std::pair<rigger_robot_RobotMode, std::uint64_t>> modes;
  cell.loop().on_data(states, [&] {
    states.take([&](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
      modes.emplace_back(s.mode, s.last_command_seq);
    });
  });
  std::size_t servo_samples = 0;
  cell.loop().on_data(servo, [&] {
    servo.take([&](const geometry_msgs_msg_dds__TwistStamped_&, const dds_sample_info_t&) { ++servo_samples; });
  });
  std::vector<std::string> names = arm.joints;
  std::vector<char*> name_ptrs;
  for (std::string& n : names) name_ptrs.push_back(n.data());
  std::vector<double> zeros(names.size(), 0.0), effort;
  cell.loop().every(10ms, [&] {
    std::vector<double> position = zeros, velocity = zeros;
    rigger_geometry_Header header{dds::wire_now(), const_cast<char*>("")};
    driver.write(ros2::to_ros2_joint_state(header, name_ptrs, position, velocity, effort));
  });
  const auto last_is = [&](rigger_robot_RobotMode mode, std::uint64_t seq) {
    return !modes.empty() && modes.back().first == mode && modes.back().second == seq;
  };
  ASSERT_TRUE(cell.wait_until([&] { return last_is(rigger_robot_ROBOT_IDLE, 0); }, 5s)) << cell.logs();
  rigger_sensing_TwistCommand c{};
  c.header.stamp = dds::wire_now();
  c.header.frame_id = const_cast<char*>("robot");
  c.seq = 4242;
  c.twist.linear.x = 0.01;
  c.timeout_s = 0.3;
  c.source = const_cast<char*>("test");
  // Written again until the bridge shows it: a reader that has matched this writer but not yet had its
  // first heartbeat drops what comes before (docs/dds.md), and wait_for_readers sees only this side.
  ASSERT_EQ(commands.write(c), DDS_RETCODE_OK);
  const auto again = cell.loop().every(50ms, [&] {
    if (!last_is(rigger_robot_ROBOT_VELOCITY, 4242)) commands.write(c);
  });
  EXPECT_TRUE(cell.wait_until([&] { return last_is(rigger_robot_ROBOT_VELOCITY, 4242); }, 2s))
      << "no ROBOT_VELOCITY state while the command is held";
  cell.loop().cancel(again);
  // After the hold (0.2 s, the shipped max_hold_s) the bridge sends Servo its zero and the state is idle again.
  EXPECT_TRUE(cell.wait_until([&] { return last_is(rigger_robot_ROBOT_IDLE, 4242) && servo_samples >= 2; }, 2s))
      << "still ROBOT_VELOCITY after the command's hold";
  cell.stop_all();
}

}  // namespace
}  // namespace rigger::testing
