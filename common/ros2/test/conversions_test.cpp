#include "rigger/ros2/conversions.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

namespace rigger::ros2 {
namespace {

rigger_sensing_WrenchStamped rigger_wrench(char* frame) {
  rigger_sensing_WrenchStamped w{};
  w.header.stamp = {1700000000, 999999999};
  w.header.frame_id = frame;
  w.wrench.force = {1.5, -2.25, std::numeric_limits<double>::denorm_min()};
  w.wrench.torque = {-0.0, 1e300, -7.0};
  return w;
}

TEST(Ros2Conversions, WrenchStampedRoundTripsFieldByField) {
  char frame[] = "ft_sensor";
  const auto in = rigger_wrench(frame);
  const auto ros = to_ros2(in);
  EXPECT_EQ(ros.header_.stamp_.sec_, 1700000000);
  EXPECT_EQ(ros.header_.stamp_.nanosec_, 999999999u);
  EXPECT_EQ(ros.header_.frame_id_, frame);  // borrowed
  EXPECT_EQ(ros.wrench_.force_.y_, -2.25);
  EXPECT_EQ(ros.wrench_.torque_.y_, 1e300);
  const auto back = to_rigger(ros);
  EXPECT_EQ(std::memcmp(&back.header.stamp, &in.header.stamp, sizeof in.header.stamp), 0);
  EXPECT_STREQ(back.header.frame_id, "ft_sensor");
  // Bit for bit, so -0 and the denormal are kept.
  EXPECT_EQ(std::memcmp(&back.wrench, &in.wrench, sizeof in.wrench), 0);
  EXPECT_TRUE(std::signbit(back.wrench.torque.x));
}

TEST(Ros2Conversions, TwistStampedCarriesHeaderAndTwistInOrder) {
  char frame[] = "base_link";
  rigger_geometry_Header h{{-5, 7}, frame};
  rigger_geometry_Twist t{{0.1, 0.2, 0.3}, {0.4, 0.5, std::nan("")}};
  const auto ros = to_ros2_twist_stamped(h, t);
  EXPECT_EQ(ros.header_.stamp_.sec_, -5);
  EXPECT_EQ(ros.header_.stamp_.nanosec_, 7u);
  EXPECT_STREQ(ros.header_.frame_id_, "base_link");
  EXPECT_EQ(ros.twist_.linear_.x_, 0.1);
  EXPECT_EQ(ros.twist_.linear_.z_, 0.3);
  EXPECT_EQ(ros.twist_.angular_.x_, 0.4);
  EXPECT_TRUE(std::isnan(ros.twist_.angular_.z_));
  const auto back = to_rigger(ros.twist_);
  EXPECT_EQ(back.linear.y, 0.2);
  EXPECT_EQ(back.angular.y, 0.5);
}

TEST(Ros2Conversions, TimeKeepsTheExtremes) {
  const rigger_geometry_Time t{std::numeric_limits<int32_t>::min(), std::numeric_limits<uint32_t>::max()};
  const auto back = to_rigger(to_ros2(t));
  EXPECT_EQ(back.sec, t.sec);
  EXPECT_EQ(back.nanosec, t.nanosec);
}

TEST(Ros2Conversions, JointStateBorrowsTheNamesAndArraysInTheirOrder) {
  char frame[] = "";
  char a1[] = "joint_a2", a2[] = "joint_a1";
  std::vector<char*> names{a1, a2};
  std::vector<double> position{0.5, -0.25}, velocity{1e-300, -0.0}, effort{};
  const auto ros = to_ros2_joint_state({{1700000000, 7}, frame}, names, position, velocity, effort);
  EXPECT_EQ(ros.header_.stamp_.sec_, 1700000000);
  EXPECT_EQ(ros.header_.stamp_.nanosec_, 7u);
  ASSERT_EQ(ros.name_._length, 2u);
  EXPECT_EQ(ros.name_._buffer, names.data());
  EXPECT_STREQ(ros.name_._buffer[0], "joint_a2");
  EXPECT_EQ(ros.position_._buffer, position.data());
  EXPECT_EQ(ros.position_._length, 2u);
  EXPECT_EQ(ros.velocity_._buffer[0], 1e-300);
  EXPECT_EQ(ros.effort_._length, 0u);
  EXPECT_FALSE(ros.name_._release || ros.position_._release || ros.velocity_._release || ros.effort_._release);
}

TEST(Ros2Conversions, CameraInfoRoundTripsAndBorrowsItsStringsAndCoefficients) {
  char frame[] = "camera";
  char model[] = "plumb_bob";
  double d[5] = {-0.2, 0.05, 0.001, -0.001, 0.0};
  rigger_vision_CameraInfo in{};
  in.header = {{1700000000, 5}, frame};
  in.height = 720;
  in.width = 1280;
  in.distortion_model = model;
  in.d = {5, 5, d, false};
  for (int i = 0; i < 9; ++i) in.k[i] = in.r[i] = i + 0.5;
  for (int i = 0; i < 12; ++i) in.p[i] = -i - 0.25;
  const sensor_msgs_msg_dds__CameraInfo_ ros = to_ros2(in);
  EXPECT_EQ(ros.header_.frame_id_, frame);
  EXPECT_EQ(ros.distortion_model_, model);
  EXPECT_EQ(ros.d_._buffer, d);
  EXPECT_FALSE(ros.d_._release);
  EXPECT_EQ(ros.d_._length, 5u);
  EXPECT_EQ(ros.height_, 720u);
  EXPECT_EQ(ros.binning_x_, 0u);  // unbinned, the full image
  EXPECT_EQ(ros.roi_.width_, 0u);
  EXPECT_FALSE(ros.roi_.do_rectify_);
  const rigger_vision_CameraInfo back = to_rigger(ros);
  EXPECT_EQ(std::memcmp(back.k, in.k, sizeof in.k), 0);
  EXPECT_EQ(std::memcmp(back.r, in.r, sizeof in.r), 0);
  EXPECT_EQ(std::memcmp(back.p, in.p, sizeof in.p), 0);
  EXPECT_EQ(back.width, 1280u);
  EXPECT_EQ(back.d._buffer, d);
  EXPECT_STREQ(back.distortion_model, "plumb_bob");
}

}  // namespace
}  // namespace rigger::ros2
