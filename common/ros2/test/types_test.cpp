#include <gtest/gtest.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <rigger/ros2/geometry_msgs.h>
#include <rigger/ros2/sensor_msgs.h>

#include <string>

namespace {

// A ROS 2 reader matches a writer on the DDS type name, so these strings are the contract with every
// ROS 2 node (rmw_cyclonedds: <pkg>::msg::dds_::<Msg>_). ROS 2 topics are keyless, and ROS 2 speaks
// plain CDR (XCDR1): a type that needed XCDR2 would be written in an encoding ROS 2 nodes do not read.
struct Expected {
  const dds_topic_descriptor_t* desc;
  const char* type_name;
};

TEST(Ros2Types, NamesKeysAndEncodingAreRos2s) {
  const Expected types[] = {
      {&builtin_interfaces_msg_dds__Time__desc, "builtin_interfaces::msg::dds_::Time_"},
      {&std_msgs_msg_dds__Header__desc, "std_msgs::msg::dds_::Header_"},
      {&geometry_msgs_msg_dds__Vector3__desc, "geometry_msgs::msg::dds_::Vector3_"},
      {&geometry_msgs_msg_dds__Point__desc, "geometry_msgs::msg::dds_::Point_"},
      {&geometry_msgs_msg_dds__Quaternion__desc, "geometry_msgs::msg::dds_::Quaternion_"},
      {&geometry_msgs_msg_dds__Pose__desc, "geometry_msgs::msg::dds_::Pose_"},
      {&geometry_msgs_msg_dds__PoseStamped__desc, "geometry_msgs::msg::dds_::PoseStamped_"},
      {&geometry_msgs_msg_dds__Twist__desc, "geometry_msgs::msg::dds_::Twist_"},
      {&geometry_msgs_msg_dds__TwistStamped__desc, "geometry_msgs::msg::dds_::TwistStamped_"},
      {&geometry_msgs_msg_dds__Wrench__desc, "geometry_msgs::msg::dds_::Wrench_"},
      {&geometry_msgs_msg_dds__WrenchStamped__desc, "geometry_msgs::msg::dds_::WrenchStamped_"},
      {&sensor_msgs_msg_dds__JointState__desc, "sensor_msgs::msg::dds_::JointState_"},
      {&sensor_msgs_msg_dds__Image__desc, "sensor_msgs::msg::dds_::Image_"},
      {&sensor_msgs_msg_dds__RegionOfInterest__desc, "sensor_msgs::msg::dds_::RegionOfInterest_"},
      {&sensor_msgs_msg_dds__CameraInfo__desc, "sensor_msgs::msg::dds_::CameraInfo_"},
  };
  for (const Expected& t : types) {
    SCOPED_TRACE(t.type_name);
    EXPECT_EQ(std::string(t.desc->m_typename), t.type_name);
    EXPECT_EQ(t.desc->m_nkeys, 0u);
    EXPECT_EQ(dds_stream_minimum_xcdr_version(t.desc->m_ops), 1u);  // CDR_ENC_VERSION_1
  }
}

}  // namespace
