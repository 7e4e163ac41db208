// The admittance controller's keys, declared once: load_control_config() reads the file with them and
// docs/config-reference.md lists them. Defaults are the structs' own (ControlConfig{}), so a default is
// written once. The ranges take in every shipped and tested file; the laws' own rules (find_problem())
// still run after them, in load_control_config().
#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <vector>

#include "control_config.hpp"

namespace rigger::control {
namespace {

using S = ControlConfig;

constexpr double kDegToRad = kPi / 180.0;
constexpr std::array<const char*, 6> kAxisNames{"x", "y", "z", "rx", "ry", "rz"};

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;

template <int N>
std::string axes_words() {
  return N == 6 ? "6 numbers (x, y, z, rx, ry, rz)" : "3 numbers (x, y, z)";
}

template <int N>
std::string vector_text(const Vec<N>& v) {
  return settings_detail::json_text(std::vector<double>(v.data(), v.data() + N));
}

// An array of N numbers, one per axis, each within `range`. An element out of range is named by its own
// pointer (".../damping/2") and axis. Absent: `when_absent` (nothing: the struct's default stays).
template <int N>
Setting<S> axes(std::string key, std::string default_text, Range<double> range, std::string unit,
                std::function<void(S&, const Vec<N>&)> set, std::function<void(S&)> when_absent,
                std::string description) {
  SettingInfo info{key,
                   "array of numbers",
                   std::move(default_text),
                   axes_words<N>() + " in " + settings_detail::range_text(range),
                   unit,
                   std::move(description)};
  return Setting<S>(std::move(info), [key, range, unit, set, when_absent](const Config& c, S& s) {
    if (!c.has(key)) {
      if (when_absent) when_absent(s);
      return;
    }
    const auto values = c.get<std::vector<double>>(key);
    if (values.size() != static_cast<std::size_t>(N))
      c.fail(key, "expected an array of " + axes_words<N>() + ", got " + std::to_string(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (std::isfinite(values[i]) && values[i] >= range.lo && values[i] <= range.hi) continue;
      std::ostringstream os;
      os << "expected a number in " << settings_detail::range_text(range) << " (" << unit << ") for axis "
         << kAxisNames[i] << ", got " << values[i];
      throw ConfigError(c.file(), c.pointer() + "/" + key + "/" + std::to_string(i), os.str());
    }
    set(s, Eigen::Map<const Vec<N>>(values.data()));
  });
}

template <int N>
Setting<S> axes(std::string key, const Vec<N>& fallback, Range<double> range, std::string unit,
                std::function<void(S&, const Vec<N>&)> set, std::string description) {
  return axes<N>(std::move(key), vector_text<N>(fallback), range, std::move(unit), std::move(set), nullptr,
                 std::move(description));
}

// An array of N booleans, one per axis.
template <std::size_t N>
Setting<S> flags(std::string key, const std::array<bool, N>& fallback,
                 std::function<void(S&, const std::array<bool, N>&)> set, std::string description) {
  std::string text;
  for (bool f : fallback) text += (text.empty() ? "" : ", ") + settings_detail::json_text(f);
  return own_setting<S>(
      key, "array of booleans", "[" + text + "]", std::to_string(N) + " booleans, one per axis",
      [set](const Config& c, const std::string& k, S& s) {
        if (!c.has(k)) return;
        const nlohmann::json& raw = c.raw(k);
        std::array<bool, N> out{};
        bool ok = raw.is_array() && raw.size() == N;
        for (std::size_t i = 0; ok && i < N; ++i) {
          ok = raw[i].is_boolean();
          if (ok) out[i] = raw[i].get<bool>();
        }
        if (!ok) c.fail(k, "expected an array of " + std::to_string(N) + " booleans, one per axis");
        set(s, out);
      },
      std::move(description));
}

std::vector<Setting<S>> robot_settings(const S& d) {
  const RobotAdmittanceConfig& r = d.robot;
  const auto gains = [](Setting<S> s) { return nested("gains", std::move(s)); };
  const auto limits = [](Setting<S> s) { return nested("limits", std::move(s)); };
  const auto tool = [](Setting<S> s) { return nested("tool", std::move(s)); };
  const auto bias = [](Setting<S> s) { return nested("sensor_bias", std::move(s)); };
  return {
      setting<S>("rate_hz", d.robot_rate_hz, {1.0, 10000.0}, &S::robot_rate_hz,
                 "the robot law's loop rate; 1/rate_hz must not exceed `max_time_step_s`"),
      choice<S>(
          "frame", r.frame, {{"base", ControlFrame::kBase}, {"tool", ControlFrame::kTool}},
          [](S& s, ControlFrame f) { s.robot.frame = f; },
          "the control frame of gains, limits, deadband, filter and the output twist: the robot's base or "
          "the tool (TCP) frame"),
      gains(axes<6>(
          "mass", r.gains.mass, {1e-3, 1e4}, "kg, kg·m²", [](S& s, const Vector6d& v) { s.robot.gains.mass = v; },
          "virtual mass M")),
      gains(axes<6>(
          "damping", r.gains.damping, {1e-3, 1e6}, "N·s/m, N·m·s/rad",
          [](S& s, const Vector6d& v) { s.robot.gains.damping = v; },
          "virtual damping D, so that free guiding (K = 0) is damped")),
      gains(axes<6>(
          "stiffness", r.gains.stiffness, {0.0, 1e6}, "N/m, N·m/rad",
          [](S& s, const Vector6d& v) { s.robot.gains.stiffness = v; }, "virtual stiffness K; 0: free guiding")),
      flags<6>(
          "selected_axes", r.selected_axes, [](S& s, const std::array<bool, 6>& f) { s.robot.selected_axes = f; },
          "the axes that respond to force; the others ignore it (a reference twist still passes on them)"),
      axes<6>(
          "deadband", r.deadband, {0.0, 1e3}, "N, N·m", [](S& s, const Vector6d& v) { s.robot.deadband = v; },
          "continuous deadband: f − sign(f)·d outside it"),
      setting<S>(
          "force_filter_cutoff_hz", r.force_filter_cutoff_hz, {0.0, 5000.0},
          [](S& s, double v) { s.robot.force_filter_cutoff_hz = v; },
          "first-order low-pass on the compensated wrench, below the loop's Nyquist rate; 0: off"),
      setting<S>(
          "reference_filter_cutoff_hz", r.reference_filter_cutoff_hz, {0.0, 5000.0},
          [](S& s, double v) { s.robot.reference_filter_cutoff_hz = v; },
          "first-order low-pass on the reference twist, which arrives in steps (a 30 Hz servo, a "
          "joystick); 0: off"),
      limits(axes<6>(
          "max_velocity", r.limits.max_velocity, {0.0, 10.0}, "m/s, rad/s",
          [](S& s, const Vector6d& v) { s.robot.limits.max_velocity = v; }, "per axis; 0 locks the axis")),
      limits(setting<S>(
          "max_linear_speed_mps", r.limits.max_linear_speed_mps, {0.0, 10.0},
          [](S& s, double v) { s.robot.limits.max_linear_speed_mps = v; },
          "limit on the norm of the linear velocity; 0: none")),
      limits(setting<S>(
          "max_angular_speed_radps", r.limits.max_angular_speed_radps, {0.0, 20.0},
          [](S& s, double v) { s.robot.limits.max_angular_speed_radps = v; },
          "limit on the norm of the angular velocity; 0: none")),
      limits(axes<6>(
          "max_acceleration", r.limits.max_acceleration, {1e-3, 100.0}, "m/s², rad/s²",
          [](S& s, const Vector6d& v) { s.robot.limits.max_acceleration = v; }, "per axis")),
      limits(axes<6>(
          "stop_deceleration", "the max_acceleration", {1e-3, 100.0}, "m/s², rad/s²",
          [](S& s, const Vector6d& v) { s.robot.limits.stop_deceleration = v; },
          [](S& s) { s.robot.limits.stop_deceleration = s.robot.limits.max_acceleration; },
          "per axis: the ramp to zero of mode OFF (a pause, a lost commander, a safe stop); a value below "
          "`max_acceleration` counts as `max_acceleration`")),
      tool(setting<S>(
          "mass_kg", r.tool.mass_kg, {0.0, 1000.0}, [](S& s, double v) { s.robot.tool.mass_kg = v; },
          "the tool (gripper) below the sensor, for weight compensation")),
      tool(axes<3>(
          "center_of_mass_m", r.tool.center_of_mass_m, {-10.0, 10.0}, "m",
          [](S& s, const Eigen::Vector3d& v) { s.robot.tool.center_of_mass_m = v; },
          "the tool's centre of mass, sensor frame")),
      bias(axes<3>(
          "force_n", r.sensor_bias.force_n, {-1e4, 1e4}, "N",
          [](S& s, const Eigen::Vector3d& v) { s.robot.sensor_bias.force_n = v; },
          "subtracted from every sample, sensor frame")),
      bias(axes<3>(
          "torque_nm", r.sensor_bias.torque_nm, {-1e3, 1e3}, "N·m",
          [](S& s, const Eigen::Vector3d& v) { s.robot.sensor_bias.torque_nm = v; },
          "subtracted from every sample, sensor frame, about the sensor origin")),
      axes<3>(
          "tcp_in_sensor_m", r.tcp_in_sensor_m, {-10.0, 10.0}, "m",
          [](S& s, const Eigen::Vector3d& v) { s.robot.tcp_in_sensor_m = v; },
          "the TCP in the sensor frame: the point whose velocity is commanded and about which torques are "
          "taken"),
      axes<3>(
          "gravity_base_mps2", r.gravity_base_mps2, {-100.0, 100.0}, "m/s²",
          [](S& s, const Eigen::Vector3d& v) { s.robot.gravity_base_mps2 = v; },
          "gravity in the base frame (a robot mounted upright: [0, 0, -9.81])"),
      setting<S>(
          "wrench_timeout_s", r.wrench_timeout.count(), {1e-4, 10.0},
          [](S& s, double v) { s.robot.wrench_timeout = Seconds(v); },
          "an older wrench sample is stale: zero output and fault WRENCH_STALE"),
      setting<S>(
          "reference_timeout_s", r.reference_timeout.count(), {1e-3, 60.0},
          [](S& s, double v) { s.robot.reference_timeout = Seconds(v); },
          "an older reference is not applied (no reference; not a fault)"),
      setting<S>(
          "max_time_step_s", r.max_time_step.count(), {1e-4, 10.0},
          [](S& s, double v) { s.robot.max_time_step = Seconds(v); },
          "a longer cycle is refused (fault TIME_STEP_INVALID, zero output)"),
      setting<S>(
          "max_plausible_force_n", r.max_plausible_force_n, {1.0, 1e5},
          [](S& s, double v) { s.robot.max_plausible_force_n = v; },
          "a larger measured force is a sensor or transport fault (WRENCH_IMPLAUSIBLE)"),
      setting<S>(
          "max_plausible_torque_nm", r.max_plausible_torque_nm, {0.1, 1e4},
          [](S& s, double v) { s.robot.max_plausible_torque_nm = v; },
          "a larger measured torque is a sensor or transport fault (WRENCH_IMPLAUSIBLE)"),
      setting<S>(
          "gain_transition_time_s", r.gain_transition_time.count(), {0.0, 60.0},
          [](S& s, double v) { s.robot.gain_transition_time = Seconds(v); },
          "a gain change is blended in over this time (smoothstep), so the output never jumps"),
  };
}

std::vector<Setting<S>> crane_settings(const S& d) {
  const CraneAdmittanceConfig& c = d.crane;
  const auto gains = [](Setting<S> s) { return nested("gains", std::move(s)); };
  return {
      setting<S>("rate_hz", d.crane_rate_hz, {1.0, 1000.0}, &S::crane_rate_hz,
                 "the crane law's loop rate; 1/rate_hz must not exceed `max_time_step_s`"),
      gains(axes<3>(
          "mass_kg", c.gains.mass_kg, {1e-3, 1e5}, "kg",
          [](S& s, const Eigen::Vector3d& v) { s.crane.gains.mass_kg = v; }, "virtual mass M_c per axis")),
      gains(axes<3>(
          "damping_ns_per_m", c.gains.damping_ns_per_m, {1e-3, 1e6}, "N·s/m",
          [](S& s, const Eigen::Vector3d& v) { s.crane.gains.damping_ns_per_m = v; }, "virtual damping D_c per axis")),
      flags<3>(
          "selected_axes", c.selected_axes, [](S& s, const std::array<bool, 3>& f) { s.crane.selected_axes = f; },
          "the axes that follow the force: bridge, trolley, hoist"),
      axes<3>(
          "deadband_n", c.deadband_n, {0.0, 1e4}, "N", [](S& s, const Eigen::Vector3d& v) { s.crane.deadband_n = v; },
          "continuous deadband"),
      setting<S>(
          "force_filter_cutoff_hz", c.force_filter_cutoff_hz, {0.0, 500.0},
          [](S& s, double v) { s.crane.force_filter_cutoff_hz = v; },
          "first-order low-pass on the force, below half the loop rate; 0: off"),
      axes<3>(
          "max_speed_mps", c.max_speed_mps, {0.0, 10.0}, "m/s",
          [](S& s, const Eigen::Vector3d& v) { s.crane.max_speed_mps = v; }, "per axis; 0 locks the axis"),
      axes<3>(
          "max_acceleration_mps2", c.max_acceleration_mps2, {1e-3, 100.0}, "m/s²",
          [](S& s, const Eigen::Vector3d& v) { s.crane.max_acceleration_mps2 = v; }, "per axis"),
      axes<3>(
          "stop_deceleration_mps2", "the max_acceleration_mps2", {1e-3, 100.0}, "m/s²",
          [](S& s, const Eigen::Vector3d& v) { s.crane.stop_deceleration_mps2 = v; },
          [](S& s) { s.crane.stop_deceleration_mps2 = s.crane.max_acceleration_mps2; },
          "the ramp to zero when disabled; a value below `max_acceleration_mps2` counts as it"),
      setting<S>(
          "robot_velocity_feedforward", c.robot_velocity_feedforward, {0.0, 1.0},
          [](S& s, double v) { s.crane.robot_velocity_feedforward = v; },
          "α: the share of the robot's velocity the crane takes over"),
      setting<S>(
          "rope_offset_gain_per_s", c.rope_offset_gain_per_s, {0.0, 100.0},
          [](S& s, double v) { s.crane.rope_offset_gain_per_s = v; },
          "k_Δ on the measured rope offset; above 0 the node needs `cell_file` and a `rope_object` with a "
          "`rope_attachment`"),
      setting<S>(
          "force_timeout_s", c.force_timeout.count(), {1e-3, 60.0},
          [](S& s, double v) { s.crane.force_timeout = Seconds(v); }, "an older force is stale"),
      setting<S>(
          "max_time_step_s", c.max_time_step.count(), {1e-4, 10.0},
          [](S& s, double v) { s.crane.max_time_step = Seconds(v); }, "a longer cycle is refused"),
      setting<S>(
          "max_plausible_force_n", c.max_plausible_force_n, {1.0, 1e6},
          [](S& s, double v) { s.crane.max_plausible_force_n = v; }, "a larger force is a sensor fault"),
      setting<S>(
          "gain_transition_time_s", c.gain_transition_time.count(), {0.0, 60.0},
          [](S& s, double v) { s.crane.gain_transition_time = Seconds(v); },
          "a gain change is blended in over this time"),
  };
}

std::vector<Setting<S>> servo_settings(const S& d) {
  const VisualServoConfig& v = d.visual_servo;
  using V3 = Eigen::Vector3d;
  return {
      axes<3>(
          "linear_gain_per_s", v.linear_gain_per_s, {0.0, 100.0}, "1/s",
          [](S& s, const V3& g) { s.visual_servo.linear_gain_per_s = g; }, "gain on the translation error, world"),
      axes<3>(
          "angular_gain_per_s", v.angular_gain_per_s, {0.0, 100.0}, "1/s",
          [](S& s, const V3& g) { s.visual_servo.angular_gain_per_s = g; }, "gain on the rotation error, world"),
      axes<3>(
          "max_linear_speed_mps", v.max_linear_speed_mps, {0.0, 10.0}, "m/s",
          [](S& s, const V3& g) { s.visual_servo.max_linear_speed_mps = g; }, "limit of the reference, per axis"),
      axes<3>(
          "max_angular_speed_radps", v.max_angular_speed_radps, {0.0, 20.0}, "rad/s",
          [](S& s, const V3& g) { s.visual_servo.max_angular_speed_radps = g; }, "limit of the reference, per axis"),
      setting<S>(
          "translation_tolerance_m", v.translation_tolerance_m, {1e-6, 1.0},
          [](S& s, double m) { s.visual_servo.translation_tolerance_m = m; },
          "converged when the load is this close to its goal …"),
      setting<S>(
          "rotation_tolerance_deg", v.rotation_tolerance_rad / kDegToRad, {1e-6, 180.0},
          [](S& s, double deg) { s.visual_servo.rotation_tolerance_rad = deg * kDegToRad; },
          "… and turned by less than this"),
      setting<S>(
          "min_quality", v.min_quality, {0.0, 1.0}, [](S& s, double q) { s.visual_servo.min_quality = q; },
          "a tracker pose of lower quality stops the reference (LOAD_QUALITY_LOW, TARGET_QUALITY_LOW)"),
      setting<S>(
          "max_pose_age_s", v.max_pose_age.count(), {1e-3, 60.0},
          [](S& s, double a) { s.visual_servo.max_pose_age = Seconds(a); },
          "an older tracker pose stops the reference (LOAD_POSE_STALE, TARGET_POSE_STALE)"),
  };
}

}  // namespace

const SettingsTable<ControlConfig>& control_settings() {
  static const SettingsTable<S> table = [] {
    const S d{};
    SettingsTable<S> t{
        setting<S>("twist_timeout_s", d.twist_timeout_s, {0.002, 1.0}, &S::twist_timeout_s,
                   "`timeout_s` of each cmd_twist"),
        setting<S>("crane_timeout_s", d.crane_timeout_s, {0.02, 2.0}, &S::crane_timeout_s,
                   "`timeout_s` of each crane cmd_velocity"),
        own_setting<S>(
            "cell_file", "path", "none", "",
            [](const Config& c, const std::string& key, S& s) {
              if (c.has(key)) s.cell_file = config_path(c, key);
            },
            "the cell file (relative to this file, then to the data folder): the robot base's pose in the world "
            "is the pose of entity `robot_id` in it; none: the base is the world frame"),
        setting<S>("robot_id", d.robot_id, &S::robot_id,
                   "the robot's entity in the cell file, and the frame id of the published cmd_twist (the robot "
                   "driver's base frame)"),
        setting<S>("crane_state_timeout_s", d.crane_state_timeout_s, {0.05, 5.0}, &S::crane_state_timeout_s,
                   "no rigger/crane/state for this long in ROBOT_AND_CRANE: CRANE_FAULT"),
        setting<S>("commander_grace_s", d.commander_grace_s, {0.1, 10.0}, &S::commander_grace_s,
                   "a command's source must be seen alive on rigger/system/service_state within this time, else "
                   "COMMANDER_LOST"),
        setting<S>("rope_object", d.rope_object, &S::rope_object,
                   "with `crane/rope_offset_gain_per_s` > 0: the tracked object whose `rope_attachment` feature "
                   "(cell file) gives the measured rope offset; needs `cell_file`"),
        setting<S>("rope_offset_max_age_s", d.rope_offset_max_age_s, {0.02, 2.0}, &S::rope_offset_max_age_s,
                   "an older tracker pose of `rope_object` gives the crane law no rope offset"),
    };
    for (auto& s : robot_settings(d)) t.push_back(nested("robot", std::move(s)));
    for (auto& s : crane_settings(d)) t.push_back(nested("crane", std::move(s)));
    for (auto& s : servo_settings(d)) t.push_back(nested("visual_servo", std::move(s)));
    return t;
  }();
  return table;
}

}  // namespace rigger::control
