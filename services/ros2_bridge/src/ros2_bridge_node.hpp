#pragma once
/// @file
/// The ROS 2 bridge's DDS plumbing (docs/ros2.md): a ROS 2 robot driver's topics on one side, rigger's
/// robot interface (rigger/protocol/robot.hpp) on the other, the boundary's checks (boundary.hpp) in
/// between. Streams, each optional in the configuration:
///   - wrench: the driver's geometry_msgs/WrenchStamped (rt/<topic>) → rigger/robot/wrench; stale,
///     future-stamped, unstamped and non-finite samples are dropped.
///   - twist_command: rigger/robot/cmd_twist → the driver's geometry_msgs/TwistStamped (MoveIt Servo);
///     stale commands are dropped, fast ones clamped or refused, and one zero twist is sent when the
///     last command's timeout passes without a newer one. A safe stop of the robot (rigger/safety/stop)
///     sends a zero twist at once and drops every command until its reset.
///   - image: a camera driver's sensor_msgs/Image (rt/<topic>) → rigger/camera/image as mono8 (colour
///     converted to grey, rows tight); stale, future-stamped and malformed images and other encodings
///     are dropped.
///   - joint_states: the driver's sensor_msgs/JointState (joint_state_broadcaster) → rigger/robot/state,
///     joints mapped by name onto the configured arm, flange and tool pose and tool twist from its
///     kinematics (kinematics.hpp); stale, future-stamped, unstamped, malformed messages, unknown,
///     repeated or missing joints and non-finite values are dropped.
/// Drops are counted and logged at most once per refusal_log_interval_s per stream and reason.
/// Everything runs on the service's event loop.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "bridge_config.hpp"
#include "joint_states.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service.hpp"

namespace rigger::ros2_bridge {

class Ros2BridgeNode : public service::Node {
 public:
  /// @throws ConfigError, DdsError.
  explicit Ros2BridgeNode(service::ServiceContext& ctx);
  /// Sends a zero twist if a command is still held, so the driver does not wait for its own timeout.
  ~Ros2BridgeNode() override;

 private:
  void on_ros2_wrench();
  void on_rigger_twist();
  void on_ros2_image();
  void on_ros2_camera_info();
  void on_ros2_joint_states();
  void send_zero_twist(const std::string& why);
  void on_safe_stop(const safety::StopState& stop);
  /// Whether a sample of `stream` stamped `stamp` passes `limits`; counts and logs the drop when not.
  bool fresh(const std::string& stream, const rigger_geometry_Time& stamp, const AgeLimits& limits);
  /// Counts an `event` ("dropped", "clamped") on `stream` for `reason` and logs it when its counter allows.
  void count(std::string_view event, const std::string& stream, std::string_view reason, const std::string& detail);

  service::ServiceContext& ctx_;
  BridgeConfig config_;
  std::optional<dds::Reader<geometry_msgs_msg_dds__WrenchStamped_>> ros2_wrench_;
  std::optional<dds::Writer<rigger_sensing_WrenchStamped>> rigger_wrench_;
  std::optional<dds::Reader<rigger_sensing_TwistCommand>> rigger_twist_;
  std::optional<dds::Writer<geometry_msgs_msg_dds__TwistStamped_>> ros2_twist_;
  std::optional<safety::SafeStopListener> safe_stop_;  // the robot's, with the twist stream
  std::optional<dds::Reader<sensor_msgs_msg_dds__Image_>> ros2_image_;
  std::optional<dds::Writer<rigger_vision_Image>> rigger_image_;
  std::vector<std::uint8_t> grey_;  // the image being forwarded (its rows tight)
  std::uint64_t image_forwarded_ = 0;
  std::optional<dds::Reader<sensor_msgs_msg_dds__CameraInfo_>> ros2_camera_info_;
  std::optional<dds::Writer<rigger_vision_CameraInfo>> rigger_camera_info_;
  std::vector<std::uint8_t> last_camera_info_;  // the intrinsics last written (their bytes, stamp left out)
  std::uint64_t camera_info_forwarded_ = 0;
  std::optional<dds::Reader<sensor_msgs_msg_dds__JointState_>> ros2_joint_states_;
  std::optional<dds::Writer<rigger_robot_RobotState>> rigger_state_;
  std::optional<JointMap> joint_map_;
  std::vector<std::string_view> joint_names_;  // the message being mapped
  std::uint64_t state_forwarded_ = 0;
  std::uint64_t last_twist_seq_ = 0;  // of the last twist command forwarded, for RobotState.last_command_seq

  std::map<std::string, RefusalCounter> refusals_;  // "<stream> <reason>"
  std::uint64_t wrench_forwarded_ = 0;
  std::uint64_t twist_forwarded_ = 0;
  std::optional<dds::EventLoop::TimerId> hold_timer_;  // set while a forwarded command is held
  std::string zero_frame_id_;                          // frame of the last forwarded command
};

}  // namespace rigger::ros2_bridge
