#include "bridge_config.hpp"

#include <fstream>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rigger::ros2_bridge {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

BridgeConfig read(const std::string& text) {
  const Config c = Config::parse(text, "ros2_bridge.json");
  BridgeConfig out = read_bridge_config(c);
  c.finish();
  return out;
}

std::string error_of(const std::string& text) {
  try {
    read(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(BridgeConfig, RosControlWithServo) {
  const auto c = read(R"({
    "ros_namespace": "/arm",
    "wrench": {"topic": "/force_torque_sensor_broadcaster/wrench", "max_age_s": 0.02},
    "twist_command": {"topic": "servo_node/delta_twist_cmds", "max_linear_mps": 0.1, "max_angular_radps": 0.2,
                      "over_limit": "refuse", "frame_id": "base_link"}
  })");
  ASSERT_TRUE(c.wrench);
  EXPECT_EQ(c.wrench->ros_topic, "/force_torque_sensor_broadcaster/wrench");  // absolute: namespace ignored
  EXPECT_EQ(c.wrench->dds_topic, "rt/force_torque_sensor_broadcaster/wrench");
  EXPECT_EQ(c.wrench->qos, Ros2Qos::kSensorData);
  EXPECT_EQ(c.wrench->age.max_age, 20ms);
  ASSERT_TRUE(c.twist);
  EXPECT_EQ(c.twist->ros_topic, "/arm/servo_node/delta_twist_cmds");
  EXPECT_EQ(c.twist->dds_topic, "rt/arm/servo_node/delta_twist_cmds");
  EXPECT_EQ(c.twist->qos, Ros2Qos::kReliableDefault);
  EXPECT_EQ(c.twist->age.max_age, 100ms);
  EXPECT_EQ(c.twist->limits.max_linear_mps, 0.1);
  EXPECT_EQ(c.twist->limits.over_limit, OverLimit::kRefuse);
  EXPECT_EQ(c.twist->frame_id, "base_link");
}

TEST(BridgeConfig, TheShippedConfigurationLoads) {
  const Config c = Config::load(std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json");
  const BridgeConfig b = read_bridge_config(c);
  c.finish();
  ASSERT_TRUE(b.wrench && b.twist && b.image);
  EXPECT_EQ(b.wrench->dds_topic, "rt/force_torque_sensor_broadcaster/wrench");
  EXPECT_EQ(b.twist->dds_topic, "rt/servo_node/delta_twist_cmds");
  EXPECT_EQ(b.image->dds_topic, "rt/camera/image_raw");
  EXPECT_EQ(b.image->qos, Ros2Qos::kSensorData);
  EXPECT_EQ(b.image->age.max_age, 200ms);
}

// A camera alone is a bridge; one stream per topic.
TEST(BridgeConfig, AnImageStreamAloneAndOneTopicPerStream) {
  const auto c = read(R"({"image": {"topic": "camera/image_raw"}})");
  ASSERT_TRUE(c.image);
  EXPECT_FALSE(c.wrench || c.twist);
  EXPECT_EQ(c.image->dds_topic, "rt/camera/image_raw");
  EXPECT_EQ(c.image->age.max_age, 200ms);  // the default
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "/x"}, "image": {"topic": "/x"}})"),
              HasSubstr("/image/topic: is the wrench topic too (/x)"));
}

// deploy/security/ros2.grants (make-pki --extra) grants the shipped configuration's ROS 2 topics: the bridge
// reads the wrench and writes the twist, the driver the other way round. A renamed topic in one file and
// not the other would leave a secured bridge unmatched.
TEST(BridgeConfig, TheShippedSecurityGrantsNameTheShippedTopics) {
  const Config c = Config::load(std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json");
  const BridgeConfig b = read_bridge_config(c);
  c.finish();
  ASSERT_TRUE(b.wrench && b.twist);
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/deploy/security/ros2.grants");
  ASSERT_TRUE(in) << "deploy/security/ros2.grants";
  std::set<std::string> grants;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') grants.insert(line);
  ASSERT_TRUE(b.image && b.joint_states);
  EXPECT_EQ(grants,
            (std::set<std::string>{
                "ros2_bridge subscribe " + b.wrench->dds_topic, "ros2_bridge subscribe " + b.joint_states->dds_topic,
                "ros2_driver publish " + b.joint_states->dds_topic, "ros2_bridge publish " + b.twist->dds_topic,
                "ros2_bridge subscribe " + b.image->dds_topic, "ros2_driver publish " + b.wrench->dds_topic,
                "ros2_driver subscribe " + b.twist->dds_topic, "ros2_driver publish " + b.image->dds_topic,
                "ros2_bridge subscribe " + b.image->camera_info_dds_topic,
                "ros2_driver publish " + b.image->camera_info_dds_topic}));
}

TEST(BridgeConfig, TheCameraInfoSitsBesideTheImageUnlessNamed) {
  const auto beside = read(R"({"image": {"topic": "/camera/image_raw"}})");
  EXPECT_EQ(beside.image->camera_info_ros_topic, "/camera/camera_info");
  EXPECT_EQ(beside.image->camera_info_dds_topic, "rt/camera/camera_info");
  const auto relative = read(R"({"ros_namespace": "/cell1", "image": {"topic": "image_raw"}})");
  EXPECT_EQ(relative.image->camera_info_ros_topic, "/cell1/camera_info");
  const auto named = read(R"({"image": {"topic": "/cam/image", "camera_info_topic": "/cam/info"}})");
  EXPECT_EQ(named.image->camera_info_dds_topic, "rt/cam/info");
  EXPECT_THAT(error_of(R"({"image": {"topic": "/cam/image", "camera_info_topic": "/cam info"}})"),
              HasSubstr("/image/camera_info_topic"));
}

TEST(BridgeConfig, QosIsChosenPerTopic) {
  const auto c = read(R"({"wrench": {"topic": "/wrench", "qos": "reliable_default"},
                          "twist_command": {"topic": "/cmd", "qos": "sensor_data"}})");
  EXPECT_EQ(c.wrench->qos, Ros2Qos::kReliableDefault);
  EXPECT_EQ(c.twist->qos, Ros2Qos::kSensorData);
  EXPECT_FALSE(read(R"({"wrench": {"topic": "/wrench"}})").twist);
}

TEST(BridgeConfig, ErrorsNameTheKey) {
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "/ft sensor/wrench"}})"),
              AllOf(HasSubstr("/wrench/topic"), HasSubstr("/ft sensor/wrench")));
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "~/wrench"}})"), HasSubstr("/wrench/topic"));
  EXPECT_THAT(error_of(R"({"wrench": {}})"), HasSubstr("/wrench/topic"));
  EXPECT_THAT(error_of(R"({"twist_command": {"topic": "/c", "qos": "best_effort"}})"), HasSubstr("/twist_command/qos"));
  EXPECT_THAT(error_of(R"({"twist_command": {"topic": "/c", "over_limit": "ignore"}})"),
              HasSubstr("/twist_command/over_limit"));
  EXPECT_THAT(error_of(R"({"twist_command": {"topic": "/c", "max_linear_mps": -1}})"),
              HasSubstr("/twist_command/max_linear_mps"));
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "/w", "max_age_s": 0}})"), HasSubstr("/wrench/max_age_s"));
  EXPECT_THAT(error_of(R"({"ros_namespace": "arm", "wrench": {"topic": "w"}})"), HasSubstr("/ros_namespace"));
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "/w", "max_agee_s": 1}})"), HasSubstr("max_agee_s"));
  EXPECT_THAT(error_of(R"({"camera_info": {"topic": "/camera_info"}})"), HasSubstr("no stream"));
  EXPECT_THAT(error_of(R"({"wrench": {"topic": "/x"}, "twist_command": {"topic": "x"}})"),
              HasSubstr("/twist_command/topic"));
}

// The reference lists each stream's keys under its section, with the stream's own defaults.
TEST(BridgeConfig, TheTableListsEachStreamsKeysWithItsDefaults) {
  const auto rows = describe(bridge_settings());
  const auto find = [&](const std::string& key) {
    for (const auto& row : rows)
      if (row.key == key) return row;
    ADD_FAILURE() << "no row " << key;
    return SettingInfo{};
  };
  EXPECT_EQ(find("wrench/topic").default_text, "required");
  EXPECT_EQ(find("wrench/max_age_s").default_text, "0.05");
  EXPECT_EQ(find("image/max_age_s").default_text, "0.2");
  EXPECT_EQ(find("twist_command/qos").default_text, "\"reliable_default\"");
  EXPECT_EQ(find("twist_command/max_hold_s").range_text, "[0.001, 10]");
  EXPECT_EQ(find("joint_states/qos").default_text, "\"system_default\"");
  EXPECT_EQ(find("joint_states/frame_id").default_text, "\"robot\"");
  EXPECT_EQ(find("joint_states/kinematics").type, "object");
  EXPECT_EQ(find("joint_states/moving_threshold_radps").unit, "rad/s");
}

// The shipped arm: the simulated iiwa 14 as DH rows, joint_state_broadcaster's topic and QoS, the magnet's
// face 0.12 m from the flange (deploy/cell/simulated_cell.json's flange_to_face_m).
TEST(BridgeConfig, TheShippedConfigurationBridgesJointStates) {
  const Config c = Config::load(std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json");
  const BridgeConfig b = read_bridge_config(c);
  c.finish();
  ASSERT_TRUE(b.joint_states);
  const JointStatesStream& j = *b.joint_states;
  EXPECT_EQ(j.dds_topic, "rt/joint_states");
  EXPECT_EQ(j.qos, Ros2Qos::kSystemDefault);
  EXPECT_EQ(j.frame_id, "robot");
  EXPECT_EQ(j.joints.size(), 7u);
  ASSERT_TRUE(j.kinematics);
  EXPECT_EQ(j.kinematics->joint_count(), 7);
  EXPECT_TRUE(j.pose_flange_tool.isApprox(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.12))));
}

std::string joint_states(const std::string& kinematics, const std::string& more = "") {
  return R"({"joint_states": {"topic": "/joint_states", "joints": ["a", "b"], "kinematics": )" + kinematics + more +
         "}}";
}

TEST(BridgeConfig, JointStatesTakeDhRowsOrAChain) {
  const auto dh = read(joint_states(R"({"dh": [{"d_m": 0.1, "alpha_deg": 90}, {"a_m": 0.2}]})",
                                    R"(, "tool": {"position_m": [0, 0, 0.05]}, "ignore_joints": ["finger"])"));
  ASSERT_TRUE(dh.joint_states && dh.joint_states->kinematics);
  EXPECT_EQ(dh.joint_states->ignore_joints, std::vector<std::string>{"finger"});
  EXPECT_EQ(dh.joint_states->age.max_age, 100ms);
  const auto chain = read(joint_states(
      R"({"chain": [{"axis": [0, 0, 1]}, {"origin": {"position_m": [0, 0, 0.1], "rpy_deg": [90, 0, 0]},
                                          "axis": [0, 0, 1]}], "flange": {"position_m": [0.2, 0, 0]}})"));
  ASSERT_TRUE(chain.joint_states && chain.joint_states->kinematics);
  // The same arm both ways: Rz(q1) Tz(0.1) Rx(90°) · Rz(q2) Tx(0.2).
  const Eigen::VectorXd q = Eigen::Vector2d(0.3, -1.1), qd = Eigen::Vector2d::Zero();
  const ArmState a = dh.joint_states->kinematics->evaluate(q, qd, Eigen::Isometry3d::Identity());
  const ArmState b = chain.joint_states->kinematics->evaluate(q, qd, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(a.pose_base_flange.isApprox(b.pose_base_flange, 1e-12));
}

TEST(BridgeConfig, JointStatesErrorsNameTheKey) {
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{"d_m": 0.1}]})")),
              AllOf(HasSubstr("/joint_states/kinematics/dh"), HasSubstr("1 entries for 2 joints")));
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{}, {}], "chain": [{}, {}]})")),
              AllOf(HasSubstr("/joint_states/kinematics"), HasSubstr("\"dh\"")));
  EXPECT_THAT(error_of(joint_states(R"({"chain": [{"axis": [0, 0, 1]}, {"axis": [0, 1, 1]}]})")),
              HasSubstr("/joint_states/kinematics/chain/1/axis"));
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{"d_m": "x"}, {}]})")), HasSubstr("/joint_states/kinematics/dh/0/d_m"));
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{}, {}]})", R"(, "tool": {"position_m": [0, 0]})")),
              HasSubstr("/joint_states/tool/position_m"));
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{}, {}]})", R"(, "ignore_joints": ["a"])")),
              AllOf(HasSubstr("/joint_states/joints"), HasSubstr("'a' is named twice")));
  EXPECT_THAT(error_of(R"({"joint_states": {"topic": "/joint_states", "kinematics": {"dh": []}}})"),
              HasSubstr("/joint_states/joints"));
  EXPECT_THAT(error_of(joint_states(R"({"dh": [{}, {}]})", R"(, "qos": "best_effort")")),
              HasSubstr("/joint_states/qos"));
}

}  // namespace
}  // namespace rigger::ros2_bridge
