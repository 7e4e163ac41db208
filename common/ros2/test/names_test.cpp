#include "rigger/ros2/names.hpp"

#include <gtest/gtest.h>

#include <string>

namespace rigger::ros2 {
namespace {

// The message of the NameError that `name` (in `ns`) raises, or "" when it is accepted.
std::string refusal(const std::string& name, const std::string& ns = "/") {
  try {
    dds_topic_name(name, ns);
  } catch (const NameError& e) {
    return e.what();
  }
  return "";
}

TEST(Ros2Names, AbsoluteNamesGetTheRtPrefix) {
  EXPECT_EQ(dds_topic_name("/wrench"), "rt/wrench");
  EXPECT_EQ(dds_topic_name("/ur/force_torque_sensor_broadcaster/wrench"),
            "rt/ur/force_torque_sensor_broadcaster/wrench");
  EXPECT_EQ(dds_topic_name("/wrench", "/ignored_for_absolute_names"), "rt/wrench");
}

TEST(Ros2Names, RelativeNamesGoUnderTheNamespace) {
  EXPECT_EQ(dds_topic_name("joint_states"), "rt/joint_states");
  EXPECT_EQ(dds_topic_name("joint_states", "/arm"), "rt/arm/joint_states");
  EXPECT_EQ(dds_topic_name("servo_node/delta_twist_cmds", "/cell_1/arm"), "rt/cell_1/arm/servo_node/delta_twist_cmds");
  EXPECT_EQ(fully_qualified_topic_name("image_raw", "/camera"), "/camera/image_raw");
}

TEST(Ros2Names, RefusesWhatRos2Refuses) {
  EXPECT_NE(refusal("").find("is empty"), std::string::npos);
  EXPECT_NE(refusal("/a//b").find("contains '//'"), std::string::npos);
  EXPECT_NE(refusal("/wrench/").find("must not end with '/'"), std::string::npos);
  EXPECT_NE(refusal("/").find("must not end with '/'"), std::string::npos);
  EXPECT_NE(refusal("/wr-ench").find("only letters, digits"), std::string::npos);
  EXPECT_NE(refusal("/wrench force").find("only letters, digits"), std::string::npos);
  EXPECT_NE(refusal("/caméra").find("only letters, digits"), std::string::npos);
  EXPECT_NE(refusal("/robot/2nd_arm").find("must not start with a digit"), std::string::npos);
  EXPECT_NE(refusal("7up").find("must not start with a digit"), std::string::npos);
  EXPECT_NE(refusal("~/wrench").find("private names"), std::string::npos);
  EXPECT_NE(refusal("/{node}/wrench").find("substitutions"), std::string::npos);
}

TEST(Ros2Names, TheRefusalSaysWhereAndWhichName) {
  EXPECT_EQ(refusal("/a/b-c"), "ROS 2 topic name '/a/b-c' at 4: only letters, digits, '_' and '/' are allowed");
}

TEST(Ros2Names, NamespaceMustBeAbsoluteAndValid) {
  EXPECT_NE(refusal("wrench", "arm").find("must be absolute"), std::string::npos);
  EXPECT_NE(refusal("wrench", "").find("ROS 2 namespace '' at 0: is empty"), std::string::npos);
  EXPECT_NE(refusal("wrench", "/arm/").find("must not end with '/'"), std::string::npos);
  EXPECT_NE(refusal("wrench", "/a//b").find("contains '//'"), std::string::npos);
}

TEST(Ros2Names, LengthLimitIsOnTheFullyQualifiedName) {
  const std::string longest = "/" + std::string(kMaxTopicNameLength - 1, 'a');
  EXPECT_EQ(dds_topic_name(longest), "rt" + longest);
  EXPECT_NE(refusal(longest + "b").find("ROS 2 allows 247"), std::string::npos);
  // Within the limit alone, too long once the namespace is put in front.
  EXPECT_NE(refusal(std::string(kMaxTopicNameLength - 2, 'a'), "/ns").find("ROS 2 allows"), std::string::npos);
}

}  // namespace
}  // namespace rigger::ros2
