#include "bridge_config.hpp"

#include "rigger/ros2/names.hpp"

namespace rigger::ros2_bridge {
namespace {

// Topic names are checked with ROS 2's rules here, so a typo fails at start instead of matching nothing.
void resolve_topic(const Config& section, const std::string& ros_namespace, Stream& stream,
                   const char* key = "topic") {
  const std::string name = stream.ros_topic;
  try {
    stream.ros_topic = ros2::fully_qualified_topic_name(name, ros_namespace);
    stream.dds_topic = ros2::dds_topic_name(name, ros_namespace);
  } catch (const ros2::NameError& e) {
    section.fail(key, e.what());
  }
}

}  // namespace

std::string_view ros2_qos_name(Ros2Qos qos) {
  switch (qos) {
    case Ros2Qos::kSensorData:
      return "sensor_data";
    case Ros2Qos::kReliableDefault:
      return "reliable_default";
    case Ros2Qos::kSystemDefault:
      return "system_default";
  }
  return "unknown";
}

BridgeConfig read_bridge_config(const Config& config) {
  BridgeConfig out;
  read_into(config, bridge_settings(), out);
  if (out.wrench) resolve_topic(config.child("wrench"), out.ros_namespace, *out.wrench);
  if (out.twist) resolve_topic(config.child("twist_command"), out.ros_namespace, *out.twist);
  if (out.image) {
    ImageStream& image = *out.image;
    if (image.camera_info_ros_topic.empty()) {
      // image_transport's convention: the camera info beside the image ("/camera/image_raw" →
      // "/camera/camera_info"), from the name as written, before it is resolved.
      const std::size_t slash = image.ros_topic.rfind('/');
      image.camera_info_ros_topic =
          (slash == std::string::npos ? std::string() : image.ros_topic.substr(0, slash + 1)) + "camera_info";
    }
    Stream info;
    info.ros_topic = image.camera_info_ros_topic;
    resolve_topic(config.child("image"), out.ros_namespace, info, "camera_info_topic");
    image.camera_info_ros_topic = info.ros_topic;
    image.camera_info_dds_topic = info.dds_topic;
    resolve_topic(config.child("image"), out.ros_namespace, image);
  }
  if (out.joint_states) resolve_topic(config.child("joint_states"), out.ros_namespace, *out.joint_states);
  if (!out.wrench && !out.twist && !out.image && !out.joint_states) {
    config.fail("",
                "configures no stream: give \"wrench\", \"twist_command\", \"image\" and/or \"joint_states\" "
                "(docs/ros2.md)");
  }
  // Each stream on a topic of its own (a DDS topic has one type).
  const std::pair<const char*, const Stream*> streams[] = {
      {"wrench", out.wrench ? &*out.wrench : nullptr},
      {"twist_command", out.twist ? &*out.twist : nullptr},
      {"image", out.image ? &*out.image : nullptr},
      {"joint_states", out.joint_states ? &*out.joint_states : nullptr}};
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (streams[i].second && streams[j].second && streams[i].second->dds_topic == streams[j].second->dds_topic)
        config.child(streams[i].first)
            .fail("topic",
                  std::string("is the ") + streams[j].first + " topic too (" + streams[j].second->ros_topic + ")");
  return out;
}

}  // namespace rigger::ros2_bridge
