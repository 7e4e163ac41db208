#pragma once
/// @file
/// The ROS 2 bridge's cell configuration (deploy/config/ros2_bridge.json, docs/ros2.md; its keys, declared
/// once in bridge_settings(), are listed in docs/config-reference.md#ros2_bridge): which ROS 2 topics of
/// the robot's driver stand for which rigger topics, with which QoS, and the age checks and limits applied
/// at the boundary. Every stream is optional; at least one must be configured.

#include <chrono>
#include <optional>
#include <string>

#include "boundary.hpp"
#include "joint_states.hpp"
#include "kinematics.hpp"
#include "rigger/base/config.hpp"
#include "rigger/ros2_bridge/settings.hpp"

namespace rigger::ros2_bridge {

/// The ROS 2 QoS profiles a bridged topic may use (rigger/ros2/qos.hpp).
enum class Ros2Qos { kSensorData, kReliableDefault, kSystemDefault };
/// "sensor_data", "reliable_default", "system_default".
std::string_view ros2_qos_name(Ros2Qos qos);

/// What every bridged stream has: the ROS 2 topic, its QoS, the age check, and a frame override.
struct Stream {
  /// Fully qualified ROS 2 name, e.g. "/force_torque_sensor_broadcaster/wrench" (as written in the file
  /// until read_bridge_config() resolves it in the namespace).
  std::string ros_topic;
  std::string dds_topic;  ///< its DDS name, "rt/force_torque_sensor_broadcaster/wrench"
  Ros2Qos qos = Ros2Qos::kSensorData;
  AgeLimits age;
  std::string frame_id;  ///< replaces the header.frame_id of the samples crossing when not empty
};

/// A ROS 2 driver's WrenchStamped (e.g. ros2_controllers' force_torque_sensor_broadcaster) → rigger's
/// robot wrench topic. Defaults: sensor_data, max age 50 ms.
struct WrenchStream : Stream {};

/// rigger's twist command → a ROS 2 TwistStamped (e.g. MoveIt Servo's delta_twist_cmds).
/// Defaults: reliable_default, max age 100 ms.
struct TwistStream : Stream {
  TwistLimits limits;
  /// Longest a command is held before the bridge sends one zero twist (the command's own timeout_s,
  /// capped by this).
  std::chrono::nanoseconds max_hold{std::chrono::milliseconds(200)};
};

/// A ROS 2 camera driver's sensor_msgs/Image → rigger/camera/image as 8-bit grey (boundary.hpp to_mono8).
/// Defaults: sensor_data, max age 200 ms.
struct ImageStream : Stream {
  /// The driver's sensor_msgs/CameraInfo beside the images (same QoS and age check) → rigger/camera/info,
  /// written when it changes. As written in the file (empty: `camera_info` beside the image topic, as
  /// image_transport places it), then resolved like the image topic.
  std::string camera_info_ros_topic;
  std::string camera_info_dds_topic;
};

/// A ROS 2 driver's sensor_msgs/JointState (joint_state_broadcaster: /joint_states) → rigger/robot/state,
/// with the flange and tool poses and the tool twist computed from the arm's kinematics. Defaults:
/// system_default QoS (joint_state_broadcaster's SystemDefaultsQoS), max age 100 ms; frame_id (the
/// robot state's base frame, the cell entity of the robot) "robot".
struct JointStatesStream : Stream {
  std::vector<std::string> joints;         ///< the arm's joint names, chain order (base to flange)
  std::vector<std::string> ignore_joints;  ///< other joints the driver publishes (e.g. a gripper's)
  std::optional<SerialChain> kinematics;   ///< always set once read
  Eigen::Isometry3d pose_flange_tool = Eigen::Isometry3d::Identity();  ///< the tool offset
  double moving_threshold_radps = 1e-3;                                ///< `moving` above this joint speed
};

struct BridgeConfig {
  std::string ros_namespace = "/";  ///< resolves relative ROS 2 topic names
  std::optional<WrenchStream> wrench;
  std::optional<TwistStream> twist;
  std::optional<ImageStream> image;
  std::optional<JointStatesStream> joint_states;
  std::chrono::nanoseconds refusal_log_interval{std::chrono::seconds(1)};
};

/// Reads the bridge's configuration with bridge_settings(), then the rules that relate several keys. Does
/// not call finish(). @throws ConfigError naming the key (e.g.
/// "/wrench/topic: '/ft sensor' is not a valid ROS 2 topic name: …").
BridgeConfig read_bridge_config(const Config& config);

}  // namespace rigger::ros2_bridge
