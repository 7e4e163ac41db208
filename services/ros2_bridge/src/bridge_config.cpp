#include "bridge_config.hpp"

#include <cmath>

#include "rigger/cell_config/cell_types.hpp"
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
  const std::string qos_name =
      c.get_enum("qos", std::string(ros2_qos_name(qos)), {"sensor_data", "reliable_default", "system_default"});
  out.qos = qos_name == "sensor_data"        ? Ros2Qos::kSensorData
            : qos_name == "reliable_default" ? Ros2Qos::kReliableDefault
                                             : Ros2Qos::kSystemDefault;
  out.age.max_age = seconds_in_range(c, "max_age_s", max_age_s, 0.001, 10.0);
  out.age.max_future_skew = seconds_in_range(c, "max_future_skew_s", 0.05, 0.0, 10.0);
  out.frame_id = c.get<std::string>("frame_id", "");
}

Eigen::Vector3d vector3(const Config& c, const std::string& key, const Eigen::Vector3d& fallback) {
  if (!c.has(key)) return fallback;
  const auto v = c.get<std::vector<double>>(key);
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    c.fail(key, "expected 3 finite numbers");
  return {v[0], v[1], v[2]};
}

// {"position_m": [x, y, z], "rpy_deg": [roll, pitch, yaw]} as in the cell file; identity when absent.
Eigen::Isometry3d read_pose(const Config& parent, const std::string& key) {
  if (!parent.has(key)) return Eigen::Isometry3d::Identity();
  const Config c = parent.child(key);
  return cell::pose_from_position_rpy_deg(vector3(c, "position_m", Eigen::Vector3d::Zero()),
                                          vector3(c, "rpy_deg", Eigen::Vector3d::Zero()));
}

double finite_number(const Config& c, const std::string& key) {
  const double v = c.get<double>(key, 0.0);
  if (!std::isfinite(v)) c.fail(key, "expected a finite number");
  return v;
}

// "dh": standard DH rows, or "chain": fixed transforms and joint axes (URDF's form); "base" and "flange" put
// the robot's base frame before the first joint and the flange after the last.
SerialChain read_kinematics(const Config& c, std::size_t joint_count) {
  constexpr double kDegToRad = M_PI / 180.0;
  if (c.has("dh") == c.has("chain"))
    c.fail("", "give the arm as \"dh\" (standard DH rows) or as \"chain\" (origins and axes)");
  const std::string key = c.has("dh") ? "dh" : "chain";
  const std::vector<Config> rows = c.children(key);
  if (rows.size() != joint_count) {
    c.fail(key, "has " + std::to_string(rows.size()) + " entries for " + std::to_string(joint_count) +
                    " joints (one per joint, chain order)");
  }
  const Eigen::Isometry3d base = read_pose(c, "base");
  const Eigen::Isometry3d flange = read_pose(c, "flange");
  try {
    if (key == "dh") {
      std::vector<DhRow> dh;
      for (const Config& r : rows)
        dh.push_back({finite_number(r, "d_m"), finite_number(r, "a_m"), finite_number(r, "alpha_deg") * kDegToRad,
                      finite_number(r, "theta_offset_deg") * kDegToRad});
      return SerialChain::from_dh(dh, base, flange);
    }
    std::vector<RevoluteJoint> joints;
    for (const Config& r : rows) {
      const Eigen::Vector3d axis = vector3(r, "axis", Eigen::Vector3d::Zero());
      if (std::abs(axis.norm() - 1.0) > 1e-6) r.fail("axis", "expected a unit vector");
      joints.push_back({read_pose(r, "origin"), axis});
    }
    joints.front().origin = base * joints.front().origin;
    return SerialChain::from_joints(joints, flange);
  } catch (const std::invalid_argument& e) {
    c.fail(key, e.what());
  }
}

JointStatesStream read_joint_states(const Config& c, const std::string& ros_namespace) {
  JointStatesStream j;
  read_stream(c, ros_namespace, Ros2Qos::kSystemDefault, 0.1, j);
  if (j.frame_id.empty()) j.frame_id = "robot";
  j.joints = c.get<std::vector<std::string>>("joints");
  if (j.joints.empty()) c.fail("joints", "expected the arm's joint names, base to flange");
  j.ignore_joints = c.get<std::vector<std::string>>("ignore_joints", {});
  try {
    JointMap check(j.joints, j.ignore_joints);
  } catch (const std::invalid_argument& e) {
    c.fail("joints", e.what());
  }
  j.kinematics = read_kinematics(c.child("kinematics"), j.joints.size());
  j.pose_flange_tool = read_pose(c, "tool");
  j.moving_threshold_radps = c.get_in_range("moving_threshold_radps", j.moving_threshold_radps, 0.0, 1.0);
  return j;
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
  if (config.has("joint_states")) out.joint_states = read_joint_states(config.child("joint_states"), out.ros_namespace);
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
            .fail("topic", std::string("is the ") + streams[j].first + " topic too (" + streams[j].second->ros_topic + ")");
  return out;
}

}  // namespace rigger::ros2_bridge
