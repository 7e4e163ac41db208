#include "bridge_config.hpp"

#include "rigger/ros2/names.hpp"

namespace rigger::ros2_bridge {
namespace {

std::chrono::nanoseconds seconds_in_range(const Config& c, const std::string& key, double fallback, double lo,
                                          double hi) {
  return from_seconds(c.get_in_range(key, fallback, lo, hi));
}

// Topic names are checked with ROS 2's rules here, so a typo fails at start instead of matching nothing.
void read_stream(const Config& c, const std::string& ros_namespace, Ros2Qos qos, double max_age_s, Stream& out) {
  const auto name = c.get<std::string>("topic");
  try {
    out.ros_topic = ros2::fully_qualified_topic_name(name, ros_namespace);
    out.dds_topic = ros2::dds_topic_name(name, ros_namespace);
  } catch (const ros2::NameError& e) {
    c.fail("topic", e.what());
  }
  const std::string qos_name = c.get_enum("qos", std::string(ros2_qos_name(qos)), {"sensor_data", "reliable_default"});
  out.qos = qos_name == "sensor_data" ? Ros2Qos::kSensorData : Ros2Qos::kReliableDefault;
  out.age.max_age = seconds_in_range(c, "max_age_s", max_age_s, 0.001, 10.0);
  out.age.max_future_skew = seconds_in_range(c, "max_future_skew_s", 0.05, 0.0, 10.0);
  out.frame_id = c.get<std::string>("frame_id", "");
}

}  // namespace

std::string_view ros2_qos_name(Ros2Qos qos) {
  return qos == Ros2Qos::kSensorData ? "sensor_data" : "reliable_default";
}

BridgeConfig read_bridge_config(const Config& config) {
  BridgeConfig out;
  out.ros_namespace = config.get<std::string>("ros_namespace", "/");
  try {
    ros2::fully_qualified_topic_name("x", out.ros_namespace);
  } catch (const ros2::NameError& e) {
    config.fail("ros_namespace", e.what());
  }
  out.refusal_log_interval = seconds_in_range(config, "refusal_log_interval_s", 1.0, 0.0, 3600.0);

  if (config.has("wrench")) {
    const Config c = config.child("wrench");
    WrenchStream w;
    read_stream(c, out.ros_namespace, Ros2Qos::kSensorData, 0.05, w);
    out.wrench = w;
  }
  if (config.has("twist_command")) {
    const Config c = config.child("twist_command");
    TwistStream t;
    read_stream(c, out.ros_namespace, Ros2Qos::kReliableDefault, 0.1, t);
    t.limits.max_linear_mps = c.get_in_range("max_linear_mps", 0.25, 0.0, 10.0);
    t.limits.max_angular_radps = c.get_in_range("max_angular_radps", 0.5, 0.0, 20.0);
    t.limits.over_limit =
        c.get_enum("over_limit", "clamp", {"clamp", "refuse"}) == "clamp" ? OverLimit::kClamp : OverLimit::kRefuse;
    t.max_hold = seconds_in_range(c, "max_hold_s", 0.2, 0.001, 10.0);
    out.twist = t;
  }
  if (config.has("image")) {
    ImageStream i;
    read_stream(config.child("image"), out.ros_namespace, Ros2Qos::kSensorData, 0.2, i);
    out.image = i;
  }
  if (!out.wrench && !out.twist && !out.image) {
    config.fail("", "configures no stream: give \"wrench\", \"twist_command\" and/or \"image\" (docs/ros2.md)");
  }
  // Each stream on a topic of its own (a DDS topic has one type).
  const std::pair<const char*, const Stream*> streams[] = {
      {"wrench", out.wrench ? &*out.wrench : nullptr},
      {"twist_command", out.twist ? &*out.twist : nullptr},
      {"image", out.image ? &*out.image : nullptr}};
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (streams[i].second && streams[j].second && streams[i].second->dds_topic == streams[j].second->dds_topic)
        config.child(streams[i].first)
            .fail("topic", std::string("is the ") + streams[j].first + " topic too (" + streams[j].second->ros_topic + ")");
  return out;
}

}  // namespace rigger::ros2_bridge
