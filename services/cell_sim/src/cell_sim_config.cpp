#include "cell_sim_config.hpp"

#include "rigger/ros2/names.hpp"

#include <cmath>
#include <limits>

#include "rigger/base/install.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/crane_protocol/crane_config.hpp"

namespace rigger::cell_sim {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

fs::path default_cell_file() { return find_data_path(kDefaultCellFile).path; }

std::uint64_t steps_per_period(double rate_hz, std::chrono::nanoseconds timestep) {
  const double steps = 1.0 / (rate_hz * std::chrono::duration<double>(timestep).count());
  return steps < 1.0 ? 1 : static_cast<std::uint64_t>(std::llround(steps));
}

namespace {

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
  out.camera_info_dds_topic = dds_name("camera_info_topic", "/camera/camera_info");
  out.joint_states_dds_topic = dds_name("joint_states_topic", "/joint_states");
  out.joint_names = c.get<std::vector<std::string>>("joint_names", out.joint_names);
  if (out.joint_names.size() != static_cast<std::size_t>(sim::kArmJointCount))
    c.fail("joint_names", "expected " + std::to_string(sim::kArmJointCount) + " names, base to flange");
  out.base_frame = c.get<std::string>("base_frame", out.base_frame);
  out.twist_timeout = std::chrono::milliseconds(c.get_in_range<int>("twist_timeout_ms", 100, 1, 10000));
  return out;
}

Eigen::Vector3d bounded_vector3(const Config& c, const std::string& key, double bound) {
  if (!c.has(key)) return Eigen::Vector3d::Zero();
  const auto v = c.get<std::vector<double>>(key);
  if (v.size() != 3 || !(std::abs(v[0]) <= bound) || !(std::abs(v[1]) <= bound) || !(std::abs(v[2]) <= bound)) {
    c.fail(key, "expected 3 numbers, each within ±" + std::to_string(bound));
  }
  return {v[0], v[1], v[2]};
}

Eigen::Isometry3d read_pose_error(const Config& c) {
  const Eigen::Vector3d position = bounded_vector3(c, "position_m", 0.5);
  const Eigen::Vector3d rpy_deg = bounded_vector3(c, "rpy_deg", 45.0);
  return cell::pose_from_position_rpy_deg(position, rpy_deg);
}

sim::DepthNoiseSettings read_depth_noise(const Config& c) {
  sim::DepthNoiseSettings out;
  out.stddev_at_1m_m = c.get_in_range("stddev_at_1m_m", 0.0, 0.0, 0.05);
  out.grazing_deg = c.get_in_range("grazing_deg", 0.0, 0.0, 89.0);
  out.edge_gap_m = c.get_in_range("edge_gap_m", 0.0, 0.0, 1.0);
  return out;
}

// A key whose value is an object, read by `read` into `field` when the file has the key.
template <typename Field, typename Read>
Setting<CellSimConfig> object_setting(const std::string& key, const std::string& default_text,
                                      Field CellSimConfig::*field, Read read, std::string doc) {
  return own_setting<CellSimConfig>(
      key, "object", default_text, "",
      [field, read](const Config& config, const std::string& k, CellSimConfig& s) {
        if (config.has(k)) s.*field = read(config.child(k));
      },
      std::move(doc));
}

}  // namespace

const SettingsTable<CellSimConfig>& cell_sim_settings() {
  using S = CellSimConfig;
  using std::chrono::milliseconds;
  const auto robot = [](Setting<S> s) { return nested("robot", std::move(s)); };
  const auto plc = [](Setting<S> s) { return nested("plc", std::move(s)); };
  const auto camera = [](Setting<S> s) { return nested("camera", std::move(s)); };
  const auto vector3 = [](std::string key, std::string fallback, auto set, std::string description) {
    return own_setting<S>(
        key, "array of numbers", std::move(fallback), "3 numbers (bridge, trolley, hoist) in [0.01, 20]",
        [set](const Config& config, const std::string& k, S& s) {
          if (config.has(k)) set(s, get_vector3(config, k, Eigen::Vector3d::Zero(), 0.01, 20.0));
        },
        std::move(description));
  };
  static const SettingsTable<S> table{
      path_setting<S>("cell_file", kDefaultCellFile, &S::cell_file,
                      "geometry, crane limits, camera: relative to this file, then to the data folder"),
      own_setting<S>(
          "model_file", "path", "the physics library's `models/cell.xml`", "",
          [](const Config& config, const std::string& key, S& s) {
            if (!config.has(key)) return;
            s.model_file = config_path(config, key);
            s.physics.model_path = s.model_file;
          },
          "the MJCF model: relative to this file, then to the data folder"),
      setting<S>(
          "real_time_factor", 1.0, {0.0, 1000.0},
          [](S& s, double f, const Config& config) {
            if (f > 0.0 && f < 0.05) config.fail("real_time_factor", "expected 0 (unpaced) or a value in [0.05, 1000]");
            s.real_time_factor = f;
          },
          "simulated seconds per wall second; 0: unpaced, else at least 0.05. Keep 1 with a crane gateway "
          "attached (the PLC's watchdog runs on simulated time); `--real-time-factor` takes its place"),
      setting<S>("max_lag_ms", 100, {1, 10000}, &S::max_lag,
                 "when the physics falls this far behind, it skips ahead instead of catching up in a burst"),
      setting<S>("realtime_priority", 0, {0, 99}, &S::realtime_priority,
                 "SCHED_FIFO priority of the physics thread; 0: the normal scheduler"),
      setting<S>("ground_truth_rate_hz", 50.0, {1.0, 1000.0}, &S::ground_truth_rate_hz,
                 "ground-truth poses per simulated second (tests and benchmarks)"),
      setting<S>("status_rate_hz", 100.0, {1.0, 1000.0}, &S::status_rate_hz,
                 "`rigger/sim/status` per simulated second"),
      robot(setting<S>("wrench_rate_hz", 1000.0, {1.0, 1000.0}, &S::wrench_rate_hz,
                       "wrench samples per simulated second")),
      robot(choice<S>("wrench_source", WrenchSource::kExternal,
                      {{"external", WrenchSource::kExternal}, {"raw", WrenchSource::kRaw}}, &S::wrench_source,
                      "`external`: the sensor reading minus the gripper's static weight; `raw`: what the sensor "
                      "reads, gripper weight included")),
      robot(setting<S>("state_rate_hz", 100.0, {1.0, 1000.0}, &S::robot_state_rate_hz,
                       "robot states per simulated second")),
      robot(setting<S>("gripper_state_rate_hz", 10.0, {1.0, 1000.0}, &S::gripper_state_rate_hz,
                       "gripper states per simulated second")),
      robot(setting<S>(
          "max_twist_timeout_ms", 500, {10, 5000},
          [](S& s, int ms) { s.physics.twist_timeout = s.max_twist_timeout = milliseconds(ms); },
          "cap on a twist command's timeout, and the physics' backstop")),
      robot(setting<S>("max_command_future_ms", 50, {0, 1000}, &S::max_command_future,
                       "how far a command's stamp may lie ahead of the simulator's clock (clock skew)")),
      robot(setting<S>("max_motion_command_age_ms", 1000, {10, 60000}, &S::max_motion_command_age,
                       "older motion commands are refused as STALE")),
      robot(nested("wrench_noise", setting<S>(
                                       "force_stddev_n", 0.0, {0.0, 100.0},
                                       [](S& s, double v) { s.physics.wrench_noise.force_stddev_n = v; },
                                       "Gaussian noise on the wrench's force"))),
      robot(nested("wrench_noise", setting<S>(
                                       "torque_stddev_nm", 0.0, {0.0, 10.0},
                                       [](S& s, double v) { s.physics.wrench_noise.torque_stddev_nm = v; },
                                       "Gaussian noise on the wrench's torque"))),
      robot(setting<S>(
          "noise_seed", 1, {0, std::numeric_limits<int>::max()},
          [](S& s, int v) { s.physics.noise_seed = static_cast<std::uint64_t>(v); }, "the noise's seed")),
      plc(setting<S>("crane_id", "crane", &S::crane_id, "the crane entity in the cell file")),
      plc(setting<S>(
          "address", "127.0.0.1", [](S& s, const std::string& v) { s.plc.server.address = v; },
          "the Modbus server's IPv4 address; `0.0.0.0`: every interface")),
      plc(setting<S>(
          "port", 1502u, {0u, 65535u}, [](S& s, unsigned v) { s.plc.server.port = static_cast<std::uint16_t>(v); },
          "the Modbus server's port; 0: an ephemeral one, reported in `rigger/sim/status` (it changes when the "
          "link is cut and restored); `--plc-port` takes its place")),
      plc(setting<S>(
          "max_clients", 4, {1, 64}, [](S& s, int v) { s.plc.server.max_clients = v; },
          "further connections are closed at once")),
      plc(setting<S>("scan_period_ms", 4, {1, 50}, &S::plc_scan_period, "the PLC's scan, in simulated time")),
      plc(setting<S>("link_up", true, &S::plc_link_up,
                     "start listening; `false`: the link is cut until `SIM_PLC_LINK` on")),
      plc(setting<S>(
          "heartbeat_timeout_ms", 200, {10, 250},
          [](S& s, int v) { s.plc.program.heartbeat_timeout = milliseconds(v); },
          "the gateway's heartbeat must change within it, else the crane quick-stops ([cell-sim.md](cell-sim.md))")),
      plc(vector3(
          "quick_stop_decel_mps2", "[2, 2, 1]",
          [](S& s, const Eigen::Vector3d& v) { s.plc.program.quick_stop_decel_mps2 = v; },
          "the quick stop's deceleration per axis; not below the crane's max acceleration")),
      plc(vector3(
          "stop_decel_mps2", "the max acceleration",
          [](S& s, const Eigen::Vector3d& v) { s.plc.program.stop_decel_mps2 = v; },
          "the ramp while a setpoint slows an axis down (a frequency converter's deceleration ramp); between the "
          "axis' max acceleration and its quick stop. Speeding up stays at the max acceleration")),
      plc(setting<S>(
          "overload_factor", 1.1, {1.0, 10.0}, [](S& s, double v) { s.plc.program.overload_factor = v; },
          "a load above the rated one times this is an overload")),
      plc(setting<S>(
          "limit_switch_tolerance_m", 0.002, {0.0, 0.5},
          [](S& s, double v) { s.plc.program.limit_switch_tolerance_m = v; },
          "how far past a travel limit the limit switch trips")),
      camera(setting<S>("enabled", true, &S::camera_enabled, "render and publish camera images")),
      camera(setting<S>("id", "camera", &S::camera_id, "the camera entity in the cell file")),
      camera(choice<S>("renderer", CameraRendererKind::kAuto,
                       {{"auto", CameraRendererKind::kAuto},
                        {"mujoco", CameraRendererKind::kMujoco},
                        {"raster", CameraRendererKind::kRaster}},
                       &S::camera_renderer,
                       "`mujoco`: MuJoCo's renderer, headless through EGL: every body the physics holds (STEP "
                       "meshes, robot, crane), the cell file's distortion, and `rigger/camera/depth`; the process "
                       "does not start without EGL. `raster`: the cell file's boxes and markers only, no "
                       "distortion, no depth image; a tenth of the CPU. `auto`: `raster` when every object of the "
                       "cell file is a box and the lens has no distortion, `mujoco` otherwise ([decision 0018](decisions/0018-the-camera-renders-"
                       "with-mujoco-when-the-cell-needs-it.md))")),
      camera(own_setting<S>(
          "rate_hz", "number", "the cell file's", "[0.1, 60]",
          [](const Config& config, const std::string& key, S& s) {
            if (config.has(key)) s.camera_rate_hz = config.get_in_range(key, 30.0, 0.1, 60.0);
          },
          "frames per simulated second")),
      camera(setting<S>("width", 0, {0, 1280}, &S::camera_width_px,
                        "image width; 0: the cell file's. With `height` (same aspect ratio); intrinsics scale")),
      camera(setting<S>("height", 0, {0, 720}, &S::camera_height_px, "image height; 0: the cell file's")),
      camera(own_setting<S>(
          "noise_stddev", "number", "the cell file's", "[0, 64]",
          [](const Config& config, const std::string& key, S& s) {
            if (config.has(key)) s.camera_noise_stddev = config.get_in_range(key, 0.0, 0.0, 64.0);
          },
          "pixel noise in grey levels")),
      camera(setting<S>("blur_sigma_px", 0.0, {0.0, 10.0}, &S::camera_blur_sigma_px, "Gaussian blur of the image (`raster` only)")),
      camera(object_setting(
          "pose_error", "none", &S::camera_pose_error, read_pose_error,
          "where the simulated camera really is against the cell file: `{\"position_m\": [x, y, z], "
          "\"rpy_deg\": [r, p, y]}` in the camera's optical frame as the file places it (each at most 0.5 m "
          "and 45°); the images are rendered from there, the cell file and `rigger/camera/info` are not "
          "changed (what a camera mounted off its drawing does)")),
      camera(object_setting(
          "depth_noise", "none", &S::camera_depth_noise, read_depth_noise,
          "what a structured-light sensor does to `rigger/camera/depth` (`mujoco` only): `stddev_at_1m_m` "
          "(noise growing with the square of the distance, [0, 0.05]), `grazing_deg` (a hole where the "
          "surface is seen further than this from its normal, [0, 89]; 0: none), `edge_gap_m` (holes on "
          "both sides of a depth step larger than this, [0, 1]; 0: none)")),
      object_setting(
          "ros2_driver", "absent", &S::ros2_driver, read_ros2_driver,
          "present (even `{}`): the robot's wrench, state and twist input and the camera's images are on ROS 2 "
          "drivers' topics instead of rigger's, for running the cell behind `ros2_bridge` ([ros2.md](ros2.md)): "
          "`geometry_msgs/WrenchStamped` written on `wrench_topic` (default "
          "`/force_torque_sensor_broadcaster/wrench`, sensor_data); `sensor_msgs/JointState` written instead of "
          "`rigger/robot/state` on `joint_states_topic` (default `/joint_states`, system_default QoS; names "
          "`joint_names`, default `joint_a1`…`joint_a7`, written last joint first; at `robot/state_rate_hz`); "
          "`geometry_msgs/TwistStamped` read on `twist_topic` (default `/servo_node/delta_twist_cmds`, "
          "reliable; each drives for `twist_timeout_ms`, default 100, in frame `base_frame`, default "
          "`base_link`); `sensor_msgs/Image` mono8 written on `image_topic` (default `/camera/image_raw`, "
          "sensor_data), each followed by its `sensor_msgs/CameraInfo` (plumb_bob, the image's stamp and frame) "
          "on `camera_info_topic` (default `/camera/camera_info`, sensor_data) instead of `rigger/camera/info`. "
          "Motions and the gripper stay on rigger's topics"),
  };
  return table;
}

CellSimConfig read_cell_sim_config(const Config& config, const std::filesystem::path& cell_file) {
  CellSimConfig out;
  read_into(config, cell_sim_settings(), out);
  if (!cell_file.empty()) out.cell_file = cell_file;
  if ((out.camera_width_px == 0) != (out.camera_height_px == 0)) {
    config.child_or_empty("camera").fail(out.camera_width_px == 0 ? "width" : "height",
                                         "expected width and height together (or neither)");
  }
  try {
    out.plc.program.limits = crane::load_crane_limits(out.cell_file.string(), out.crane_id);
    plc::validate(out.plc.program);
  } catch (const crane::CraneConfigError& e) {
    if (!cell_file.empty()) throw ConfigError(cell_file.string(), "", e.what());
    config.fail(config.has("cell_file") ? "cell_file" : "", e.what());
  } catch (const plc::PlcConfigError& e) {
    config.fail("plc", e.what());
  }
  return out;
}

}  // namespace rigger::cell_sim
