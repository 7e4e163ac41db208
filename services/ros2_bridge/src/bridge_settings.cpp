// The bridge's keys, declared once: read_bridge_config() reads the file with them and
// docs/config-reference.md lists them. A stream's keys are read only when its section is given; its
// topic and the joint states' joints and kinematics have no default.
#include <cmath>
#include <optional>
#include <stdexcept>

#include "bridge_config.hpp"
#include "rigger/base/time.hpp"
#include "rigger/cell_config/cell_types.hpp"
#include "rigger/ros2/names.hpp"

namespace rigger::ros2_bridge {
namespace {

using S = BridgeConfig;

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

// `inner`, read from the object `section` of the file only when it is there: the stream is bridged then.
template <typename T>
Setting<S> in_stream(const std::string& section, std::optional<T> S::*stream, Setting<T> inner) {
  SettingInfo info = inner.info();
  info.key = section + "/" + info.key;
  return Setting<S>(std::move(info), [section, stream, inner = std::move(inner)](const Config& config, S& s) {
    if (!config.has(section)) return;
    std::optional<T>& out = s.*stream;
    if (!out) out.emplace();
    inner.read(config.child(section), *out);
  });
}

// A frame id that replaces the header.frame_id of the samples crossing when not empty.
template <typename T>
Setting<T> frame_override(const std::string& samples) {
  return setting<T>(
      "frame_id", "", [](T& t, const std::string& v) { t.frame_id = v; },
      "replaces the header.frame_id of the " + samples + " crossing when not empty");
}

// The keys every stream has; `qos` and `max_age_s` with the stream's defaults, and its `frame_id`.
template <typename T>
std::vector<Setting<T>> stream_settings(Ros2Qos qos, double max_age_s, Setting<T> frame_id) {
  return {
      own_setting<T>(
          "topic", "string", "required", "",
          [](const Config& c, const std::string& key, T& t) { t.ros_topic = c.get<std::string>(key); },
          "the ROS 2 topic, checked with ROS 2's rules; a relative name is resolved in `ros_namespace`. Giving "
          "the section bridges the stream"),
      choice<T>(
          "qos", qos,
          {{"sensor_data", Ros2Qos::kSensorData},
           {"reliable_default", Ros2Qos::kReliableDefault},
           {"system_default", Ros2Qos::kSystemDefault}},
          [](T& t, Ros2Qos q) { t.qos = q; }, "the ROS 2 QoS profile of the topic"),
      setting<T>(
          "max_age_s", max_age_s, {0.001, 10.0}, [](T& t, double v) { t.age.max_age = from_seconds(v); },
          "an older sample is refused"),
      setting<T>(
          "max_future_skew_s", 0.05, {0.0, 10.0}, [](T& t, double v) { t.age.max_future_skew = from_seconds(v); },
          "a sample stamped further ahead of the bridge's clock is refused"),
      std::move(frame_id),
  };
}

template <typename T>
void add_stream(SettingsTable<S>& table, const std::string& section, std::optional<T> S::*stream,
                std::vector<Setting<T>> settings) {
  for (auto& s : settings) table.push_back(in_stream(section, stream, std::move(s)));
}

std::vector<Setting<TwistStream>> twist_settings() {
  using T = TwistStream;
  auto out = stream_settings<T>(Ros2Qos::kReliableDefault, 0.1, frame_override<T>("twists"));
  const T d{};
  out.push_back(setting<T>(
      "max_linear_mps", d.limits.max_linear_mps, {0.0, 10.0}, [](T& t, double v) { t.limits.max_linear_mps = v; },
      "limit on the linear speed"));
  out.push_back(setting<T>(
      "max_angular_radps", d.limits.max_angular_radps, {0.0, 20.0},
      [](T& t, double v) { t.limits.max_angular_radps = v; }, "limit on the angular speed"));
  out.push_back(choice<T>(
      "over_limit", d.limits.over_limit, {{"clamp", OverLimit::kClamp}, {"refuse", OverLimit::kRefuse}},
      [](T& t, OverLimit o) { t.limits.over_limit = o; },
      "a twist above a limit: `clamp` scales it down, `refuse` drops it"));
  out.push_back(setting<T>(
      "max_hold_s", 0.2, {0.001, 10.0}, [](T& t, double v) { t.max_hold = from_seconds(v); },
      "the longest a command is held (its own timeout_s, capped by this) before the bridge "
      "sends one zero twist"));
  return out;
}

std::vector<Setting<JointStatesStream>> joint_states_settings() {
  using T = JointStatesStream;
  auto out = stream_settings<T>(
      Ros2Qos::kSystemDefault, 0.1,
      setting<T>(
          "frame_id", "robot", [](T& t, const std::string& v) { t.frame_id = v.empty() ? "robot" : v; },
          "the robot state's base frame, the cell entity of the robot; empty: `robot`"));
  out.push_back(own_setting<T>(
      "joints", "array of strings", "required", "",
      [](const Config& c, const std::string& key, T& t) {
        t.joints = c.get<std::vector<std::string>>(key);
        if (t.joints.empty()) c.fail(key, "expected the arm's joint names, base to flange");
      },
      "the arm's joint names in chain order, base to flange"));
  out.push_back(setting<T>(
      "ignore_joints", std::vector<std::string>{},
      [](T& t, const std::vector<std::string>& v, const Config& c) {
        t.ignore_joints = v;
        try {
          JointMap check(t.joints, t.ignore_joints);
        } catch (const std::invalid_argument& e) {
          c.fail("joints", e.what());
        }
      },
      "other joints the driver publishes (e.g. a gripper's); any other joint is refused"));
  out.push_back(own_setting<T>(
      "kinematics", "object", "required", "",
      [](const Config& c, const std::string& key, T& t) {
        t.kinematics = read_kinematics(c.child(key), t.joints.size());
      },
      "the arm, one entry per joint: `dh`, standard DH rows (`d_m`, `a_m`, `alpha_deg`, `theta_offset_deg`, each 0 "
      "when absent), or `chain`, per joint an "
      "`origin` pose and a unit `axis` (URDF's form); `base` and `flange` poses before the first joint and after "
      "the last ([ros2.md](ros2.md))"));
  out.push_back(own_setting<T>(
      "tool", "object", "identity", "",
      [](const Config& c, const std::string& key, T& t) { t.pose_flange_tool = read_pose(c, key); },
      "the tool in the flange frame, `{\"position_m\": [x, y, z], \"rpy_deg\": [roll, pitch, yaw]}`"));
  out.push_back(setting<T>("moving_threshold_radps", T{}.moving_threshold_radps, {0.0, 1.0}, &T::moving_threshold_radps,
                           "the robot state says `moving` above this joint speed"));
  return out;
}

}  // namespace

const SettingsTable<BridgeConfig>& bridge_settings() {
  static const SettingsTable<S> table = [] {
    SettingsTable<S> t{
        setting<S>(
            "ros_namespace", "/",
            [](S& s, const std::string& v, const Config& c) {
              try {
                ros2::fully_qualified_topic_name("x", v);
              } catch (const ros2::NameError& e) {
                c.fail("ros_namespace", e.what());
              }
              s.ros_namespace = v;
            },
            "resolves relative ROS 2 topic names"),
        setting<S>(
            "refusal_log_interval_s", 1.0, {0.0, 3600.0},
            [](S& s, double v) { s.refusal_log_interval = from_seconds(v); },
            "each drop reason of each stream is logged at most once per this interval, with the count since the last "
            "line and the total"),
    };
    add_stream(t, "wrench", &S::wrench,
               stream_settings<WrenchStream>(Ros2Qos::kSensorData, 0.05, frame_override<WrenchStream>("wrenches")));
    add_stream(t, "twist_command", &S::twist, twist_settings());
    std::vector<Setting<ImageStream>> image =
        stream_settings<ImageStream>(Ros2Qos::kSensorData, 0.2, frame_override<ImageStream>("images"));
    image.push_back(setting<ImageStream>(
        "camera_info_topic", "", [](ImageStream& s, const std::string& v) { s.camera_info_ros_topic = v; },
        "the driver's `sensor_msgs/CameraInfo` (same QoS and age check), bridged to `rigger/camera/info` when it "
        "changes; empty: `camera_info` beside the image topic (image_transport's place). Refused unless "
        "plumb_bob (or no model and no coefficients), finite, unbinned and of the full image"));
    add_stream(t, "image", &S::image, std::move(image));
    add_stream(t, "joint_states", &S::joint_states, joint_states_settings());
    return t;
  }();
  return table;
}

}  // namespace rigger::ros2_bridge
