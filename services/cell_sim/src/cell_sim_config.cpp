#include "cell_sim_config.hpp"

#include "rigger/ros2/names.hpp"

#include <cmath>
#include <limits>

#include "rigger/base/install.hpp"
#include "rigger/crane_protocol/crane_config.hpp"

namespace rigger::cell_sim {
namespace {

namespace fs = std::filesystem;

std::chrono::milliseconds get_ms(const Config& config, const std::string& key, std::chrono::milliseconds fallback,
                                 int lo, int hi) {
  return std::chrono::milliseconds(config.get_in_range<int>(key, static_cast<int>(fallback.count()), lo, hi));
}

Eigen::Vector3d get_vector3(const Config& config, const std::string& key, const Eigen::Vector3d& fallback, double lo,
                            double hi) {
  if (!config.has(key)) return fallback;
  const auto values = config.get<std::vector<double>>(key);
  if (values.size() != 3)
    config.fail(key, "expected 3 numbers (bridge, trolley, hoist), got " + std::to_string(values.size()));
  for (double v : values) {
    if (!std::isfinite(v) || v < lo || v > hi) {
      config.fail(key, "expected numbers in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
  }
  return {values[0], values[1], values[2]};
}

void read_robot(const Config& robot, CellSimConfig& out) {
  out.wrench_rate_hz = robot.get_in_range("wrench_rate_hz", out.wrench_rate_hz, 1.0, 1000.0);
  out.wrench_source = robot.get_enum("wrench_source", "external", {"external", "raw"}) == "raw"
                          ? WrenchSource::kRaw
                          : WrenchSource::kExternal;
  out.robot_state_rate_hz = robot.get_in_range("state_rate_hz", out.robot_state_rate_hz, 1.0, 1000.0);
  out.gripper_state_rate_hz = robot.get_in_range("gripper_state_rate_hz", out.gripper_state_rate_hz, 1.0, 1000.0);
  out.max_twist_timeout = get_ms(robot, "max_twist_timeout_ms", out.max_twist_timeout, 10, 5000);
  out.physics.twist_timeout = out.max_twist_timeout;
  out.max_command_future = get_ms(robot, "max_command_future_ms", out.max_command_future, 0, 1000);
  out.max_motion_command_age = get_ms(robot, "max_motion_command_age_ms", out.max_motion_command_age, 10, 60000);
  const Config noise = robot.child_or_empty("wrench_noise");
  out.physics.wrench_noise.force_stddev_n = noise.get_in_range("force_stddev_n", 0.0, 0.0, 100.0);
  out.physics.wrench_noise.torque_stddev_nm = noise.get_in_range("torque_stddev_nm", 0.0, 0.0, 10.0);
  out.physics.noise_seed =
      static_cast<std::uint64_t>(robot.get_in_range<int>("noise_seed", 1, 0, std::numeric_limits<int>::max()));
}

void read_plc(const Config& plc, CellSimConfig& out) {
  out.crane_id = plc.get<std::string>("crane_id", out.crane_id);
  out.plc.server.address = plc.get<std::string>("address", out.plc.server.address);
  out.plc.server.port = plc.get<std::uint16_t>("port", 1502);
  out.plc.server.max_clients = plc.get_in_range("max_clients", out.plc.server.max_clients, 1, 64);
  out.plc_scan_period = get_ms(plc, "scan_period_ms", out.plc_scan_period, 1, 50);
  out.plc_link_up = plc.get<bool>("link_up", out.plc_link_up);
  auto& program = out.plc.program;
  program.heartbeat_timeout = get_ms(plc, "heartbeat_timeout_ms", std::chrono::milliseconds(200), 10, 250);
  program.quick_stop_decel_mps2 = get_vector3(plc, "quick_stop_decel_mps2", program.quick_stop_decel_mps2, 0.01, 20.0);
  if (plc.has("stop_decel_mps2"))
    program.stop_decel_mps2 = get_vector3(plc, "stop_decel_mps2", Eigen::Vector3d::Zero(), 0.01, 20.0);
  program.overload_factor = plc.get_in_range("overload_factor", program.overload_factor, 1.0, 10.0);
  program.limit_switch_tolerance_m =
      plc.get_in_range("limit_switch_tolerance_m", program.limit_switch_tolerance_m, 0.0, 0.5);
}

void read_camera(const Config& camera, CellSimConfig& out) {
  out.camera_enabled = camera.get<bool>("enabled", out.camera_enabled);
  out.camera_id = camera.get<std::string>("id", out.camera_id);
  if (camera.has("rate_hz")) out.camera_rate_hz = camera.get_in_range("rate_hz", 30.0, 0.1, 60.0);
  out.camera_width_px = camera.get_in_range("width", 0, 0, 1280);
  out.camera_height_px = camera.get_in_range("height", 0, 0, 720);
  if ((out.camera_width_px == 0) != (out.camera_height_px == 0)) {
    camera.fail(out.camera_width_px == 0 ? "width" : "height", "expected width and height together (or neither)");
  }
  if (camera.has("noise_stddev")) out.camera_noise_stddev = camera.get_in_range("noise_stddev", 0.0, 0.0, 64.0);
  out.camera_blur_sigma_px = camera.get_in_range("blur_sigma_px", out.camera_blur_sigma_px, 0.0, 10.0);
}

}  // namespace

fs::path default_cell_file() { return find_data_path(kDefaultCellFile).path; }

std::uint64_t steps_per_period(double rate_hz, std::chrono::nanoseconds timestep) {
  const double steps = 1.0 / (rate_hz * std::chrono::duration<double>(timestep).count());
  return steps < 1.0 ? 1 : static_cast<std::uint64_t>(std::llround(steps));
}

CellSimConfig::Ros2Driver read_ros2_driver(const Config& c) {
  CellSimConfig::Ros2Driver out;
  const auto dds_name = [&](const char* key, const char* fallback) {
    try {
      return ros2::dds_topic_name(c.get<std::string>(key, fallback), "/");
    } catch (const ros2::NameError& e) {
      c.fail(key, e.what());
    }
  };
  out.wrench_dds_topic = dds_name("wrench_topic", "/force_torque_sensor_broadcaster/wrench");
  out.twist_dds_topic = dds_name("twist_topic", "/servo_node/delta_twist_cmds");
  out.image_dds_topic = dds_name("image_topic", "/camera/image_raw");
  out.joint_states_dds_topic = dds_name("joint_states_topic", "/joint_states");
  out.joint_names = c.get<std::vector<std::string>>("joint_names", out.joint_names);
  if (out.joint_names.size() != static_cast<std::size_t>(sim::kArmJointCount))
    c.fail("joint_names", "expected " + std::to_string(sim::kArmJointCount) + " names, base to flange");
  out.base_frame = c.get<std::string>("base_frame", out.base_frame);
  out.twist_timeout = get_ms(c, "twist_timeout_ms", out.twist_timeout, 1, 10000);
  return out;
}

CellSimConfig read_cell_sim_config(const Config& config) {
  CellSimConfig out;
  out.cell_file = config_path(config, "cell_file", kDefaultCellFile);
  if (config.has("model_file")) {
    out.model_file = config_path(config, "model_file");
    out.physics.model_path = out.model_file;
  }
  out.real_time_factor = config.get_in_range("real_time_factor", out.real_time_factor, 0.0, 1000.0);
  if (out.real_time_factor > 0.0 && out.real_time_factor < 0.05) {
    config.fail("real_time_factor", "expected 0 (unpaced) or a value in [0.05, 1000]");
  }
  out.max_lag = get_ms(config, "max_lag_ms", out.max_lag, 1, 10000);
  out.realtime_priority = config.get_in_range("realtime_priority", out.realtime_priority, 0, 99);
  out.ground_truth_rate_hz = config.get_in_range("ground_truth_rate_hz", out.ground_truth_rate_hz, 1.0, 1000.0);
  out.status_rate_hz = config.get_in_range("status_rate_hz", out.status_rate_hz, 1.0, 1000.0);
  read_robot(config.child_or_empty("robot"), out);
  read_plc(config.child_or_empty("plc"), out);
  read_camera(config.child_or_empty("camera"), out);
  if (config.has("ros2_driver")) out.ros2_driver = read_ros2_driver(config.child("ros2_driver"));

  try {
    out.plc.program.limits = crane::load_crane_limits(out.cell_file.string(), out.crane_id);
    plc::validate(out.plc.program);
  } catch (const crane::CraneConfigError& e) {
    config.fail(config.has("cell_file") ? "cell_file" : "", e.what());
  } catch (const plc::PlcConfigError& e) {
    config.fail("plc", e.what());
  }
  return out;
}

}  // namespace rigger::cell_sim
