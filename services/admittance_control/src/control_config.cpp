#include "control_config.hpp"

#include <array>
#include <cmath>
#include <vector>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::control {
namespace {

constexpr double kDegToRad = kPi / 180.0;

template <int N>
Eigen::Matrix<double, N, 1> read_vector(const Config& config, const std::string& key,
                                        const Eigen::Matrix<double, N, 1>& fallback) {
  if (!config.has(key)) return fallback;
  const auto values = config.get<std::vector<double>>(key);
  if (values.size() != static_cast<std::size_t>(N))
    config.fail(key, "expected an array of " + std::to_string(N) +
                         (N == 6 ? " numbers (x, y, z, rx, ry, rz)" : " numbers (x, y, z)") + ", got " +
                         std::to_string(values.size()));
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(values.data());
}

template <std::size_t N>
std::array<bool, N> read_flags(const Config& config, const std::string& key, const std::array<bool, N>& fallback) {
  if (!config.has(key)) return fallback;
  const nlohmann::json& raw = config.raw(key);
  std::array<bool, N> out{};
  if (raw.is_array() && raw.size() == N) {
    bool all_booleans = true;
    for (std::size_t i = 0; i < N; ++i) {
      all_booleans = all_booleans && raw[i].is_boolean();
      if (all_booleans) out[i] = raw[i].get<bool>();
    }
    if (all_booleans) return out;
  }
  config.fail(key, "expected an array of " + std::to_string(N) + " booleans, one per axis");
}

Seconds read_seconds(const Config& config, const std::string& key, Seconds fallback) {
  return Seconds(config.get<double>(key, fallback.count()));
}

// Turns a find_problem() result into the file's error.
template <typename T>
void check(const T& value, const Config& section) {
  if (auto p = find_problem(value)) throw ConfigError(section.file(), section.pointer() + p->pointer, p->problem);
}

RobotAdmittanceConfig read_robot(const Config& c) {
  RobotAdmittanceConfig r;
  const auto frame = c.get_enum("frame", std::string(to_string(r.frame)), {"base", "tool"});
  r.frame = *control_frame_from_string(frame);
  const Config gains = c.child_or_empty("gains");
  r.gains.mass = read_vector<6>(gains, "mass", r.gains.mass);
  r.gains.damping = read_vector<6>(gains, "damping", r.gains.damping);
  r.gains.stiffness = read_vector<6>(gains, "stiffness", r.gains.stiffness);
  r.selected_axes = read_flags<6>(c, "selected_axes", r.selected_axes);
  r.deadband = read_vector<6>(c, "deadband", r.deadband);
  r.force_filter_cutoff_hz = c.get<double>("force_filter_cutoff_hz", r.force_filter_cutoff_hz);
  r.reference_filter_cutoff_hz = c.get<double>("reference_filter_cutoff_hz", r.reference_filter_cutoff_hz);
  const Config limits = c.child_or_empty("limits");
  r.limits.max_velocity = read_vector<6>(limits, "max_velocity", r.limits.max_velocity);
  r.limits.max_linear_speed_mps = limits.get<double>("max_linear_speed_mps", r.limits.max_linear_speed_mps);
  r.limits.max_angular_speed_radps = limits.get<double>("max_angular_speed_radps", r.limits.max_angular_speed_radps);
  r.limits.max_acceleration = read_vector<6>(limits, "max_acceleration", r.limits.max_acceleration);
  r.limits.stop_deceleration = read_vector<6>(limits, "stop_deceleration", r.limits.max_acceleration);
  const Config tool = c.child_or_empty("tool");
  r.tool.mass_kg = tool.get<double>("mass_kg", r.tool.mass_kg);
  r.tool.center_of_mass_m = read_vector<3>(tool, "center_of_mass_m", r.tool.center_of_mass_m);
  const Config bias = c.child_or_empty("sensor_bias");
  r.sensor_bias.force_n = read_vector<3>(bias, "force_n", r.sensor_bias.force_n);
  r.sensor_bias.torque_nm = read_vector<3>(bias, "torque_nm", r.sensor_bias.torque_nm);
  r.tcp_in_sensor_m = read_vector<3>(c, "tcp_in_sensor_m", r.tcp_in_sensor_m);
  r.gravity_base_mps2 = read_vector<3>(c, "gravity_base_mps2", r.gravity_base_mps2);
  r.wrench_timeout = read_seconds(c, "wrench_timeout_s", r.wrench_timeout);
  r.reference_timeout = read_seconds(c, "reference_timeout_s", r.reference_timeout);
  r.max_time_step = read_seconds(c, "max_time_step_s", r.max_time_step);
  r.max_plausible_force_n = c.get<double>("max_plausible_force_n", r.max_plausible_force_n);
  r.max_plausible_torque_nm = c.get<double>("max_plausible_torque_nm", r.max_plausible_torque_nm);
  r.gain_transition_time = read_seconds(c, "gain_transition_time_s", r.gain_transition_time);
  check(r, c);
  return r;
}

CraneAdmittanceConfig read_crane(const Config& c) {
  CraneAdmittanceConfig r;
  const Config gains = c.child_or_empty("gains");
  r.gains.mass_kg = read_vector<3>(gains, "mass_kg", r.gains.mass_kg);
  r.gains.damping_ns_per_m = read_vector<3>(gains, "damping_ns_per_m", r.gains.damping_ns_per_m);
  r.selected_axes = read_flags<3>(c, "selected_axes", r.selected_axes);
  r.deadband_n = read_vector<3>(c, "deadband_n", r.deadband_n);
  r.force_filter_cutoff_hz = c.get<double>("force_filter_cutoff_hz", r.force_filter_cutoff_hz);
  r.max_speed_mps = read_vector<3>(c, "max_speed_mps", r.max_speed_mps);
  r.max_acceleration_mps2 = read_vector<3>(c, "max_acceleration_mps2", r.max_acceleration_mps2);
  r.stop_deceleration_mps2 = read_vector<3>(c, "stop_deceleration_mps2", r.max_acceleration_mps2);
  r.robot_velocity_feedforward = c.get<double>("robot_velocity_feedforward", r.robot_velocity_feedforward);
  r.rope_offset_gain_per_s = c.get<double>("rope_offset_gain_per_s", r.rope_offset_gain_per_s);
  r.force_timeout = read_seconds(c, "force_timeout_s", r.force_timeout);
  r.max_time_step = read_seconds(c, "max_time_step_s", r.max_time_step);
  r.max_plausible_force_n = c.get<double>("max_plausible_force_n", r.max_plausible_force_n);
  r.gain_transition_time = read_seconds(c, "gain_transition_time_s", r.gain_transition_time);
  check(r, c);
  return r;
}

VisualServoConfig read_servo(const Config& c) {
  VisualServoConfig r;
  r.linear_gain_per_s = read_vector<3>(c, "linear_gain_per_s", r.linear_gain_per_s);
  r.angular_gain_per_s = read_vector<3>(c, "angular_gain_per_s", r.angular_gain_per_s);
  r.max_linear_speed_mps = read_vector<3>(c, "max_linear_speed_mps", r.max_linear_speed_mps);
  r.max_angular_speed_radps = read_vector<3>(c, "max_angular_speed_radps", r.max_angular_speed_radps);
  r.translation_tolerance_m = c.get<double>("translation_tolerance_m", r.translation_tolerance_m);
  r.rotation_tolerance_rad =
      c.get_in_range<double>("rotation_tolerance_deg", r.rotation_tolerance_rad / kDegToRad, 1e-6, 180.0) * kDegToRad;
  r.min_quality = c.get<double>("min_quality", r.min_quality);
  r.max_pose_age = read_seconds(c, "max_pose_age_s", r.max_pose_age);
  check(r, c);
  return r;
}

std::string json_kind(const nlohmann::json& value) {
  if (value.is_object()) return "an object";
  if (value.is_array()) return "an array";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_number()) return "a number";
  return "null";
}

Eigen::Vector3d read_triple(const nlohmann::json& object, const char* key, const std::string& source,
                            const std::string& pointer) {
  const std::string where = pointer + "/" + key;
  const auto it = object.find(key);
  if (it == object.end()) throw ConfigError(source, where, "missing required key");
  if (it->is_array() && it->size() == 3) {
    Eigen::Vector3d out;
    bool ok = true;
    for (std::size_t i = 0; i < 3 && ok; ++i) {
      ok = (*it)[i].is_number() && std::isfinite((*it)[i].get<double>());
      if (ok) out[static_cast<Eigen::Index>(i)] = (*it)[i].get<double>();
    }
    if (ok) return out;
  }
  throw ConfigError(source, where, "expected an array of 3 finite numbers, got " + json_kind(*it));
}

}  // namespace

ControlConfig load_control_config(const Config& config) {
  ControlConfig out;
  const Config robot = config.child_or_empty("robot");
  out.robot_rate_hz = robot.get_in_range<double>("rate_hz", out.robot_rate_hz, 1.0, 10000.0);
  out.robot = read_robot(robot);
  const Config crane = config.child_or_empty("crane");
  out.crane_rate_hz = crane.get_in_range<double>("rate_hz", out.crane_rate_hz, 1.0, 1000.0);
  out.crane = read_crane(crane);
  out.visual_servo = read_servo(config.child_or_empty("visual_servo"));
  // The laws refuse a step longer than max_time_step: a loop period above it would fault every cycle.
  if (1.0 / out.robot_rate_hz > out.robot.max_time_step.count())
    robot.fail("rate_hz", "the period 1/rate_hz must not exceed max_time_step_s");
  if (1.0 / out.crane_rate_hz > out.crane.max_time_step.count())
    crane.fail("rate_hz", "the period 1/rate_hz must not exceed max_time_step_s");
  config.finish();
  return out;
}

ControlConfig load_control_config_file(const std::string& path) {
  return load_control_config(Config::load(path));
}

Eigen::Isometry3d pose_from_config_json(const nlohmann::json& value, const std::string& source,
                                        const std::string& pointer) {
  if (!value.is_object())
    throw ConfigError(source, pointer,
                      "expected an object {\"position_m\": [..], \"rpy_deg\": [..]}, got " + json_kind(value));
  for (const auto& item : value.items())
    if (item.key() != "position_m" && item.key() != "rpy_deg" && item.key() != "comment")
      throw ConfigError(source, pointer + "/" + item.key(), "unknown key (expected position_m and rpy_deg)");
  const Eigen::Vector3d position_m = read_triple(value, "position_m", source, pointer);
  const Eigen::Vector3d rpy_rad = read_triple(value, "rpy_deg", source, pointer) * kDegToRad;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = position_m;
  return pose;
}

Eigen::Isometry3d insertion_offset_from_features(const nlohmann::json& features, const std::string& source) {
  if (!features.is_object()) throw ConfigError(source, "", "expected the features object, got " + json_kind(features));
  const auto insertion = features.find("insertion");
  if (insertion == features.end() || !insertion->is_object())
    throw ConfigError(source, "/insertion", "expected an object with pose_in_target (the object has no insertion)");
  const auto pose = insertion->find("pose_in_target");
  if (pose == insertion->end()) throw ConfigError(source, "/insertion/pose_in_target", "missing required key");
  return pose_from_config_json(*pose, source, "/insertion/pose_in_target");
}

Eigen::Isometry3d entity_pose_from_cell_file(const std::string& path, const std::string& entity_id) {
  cell::CellFile cell;
  try {
    cell = cell::load_cell_file(path);  // the one cell-file reader: bounded, every rule checked
  } catch (const cell::CellFileError& e) {
    throw ConfigError(path, e.pointer(), e.what());
  }
  const cell::CellEntity* entity = cell.find(entity_id);
  if (entity == nullptr) throw ConfigError(path, "/entities", "no entity with id '" + entity_id + "'");
  if (entity->parent != "world")
    throw ConfigError(path, entity->pointer + "/parent",
                      "entity '" + entity_id + "' must have parent 'world', got '" + entity->parent + "'");
  if (!entity->pose_parent_entity) throw ConfigError(path, entity->pointer + "/pose", "missing required key");
  return *entity->pose_parent_entity;
}

}  // namespace rigger::control
