#pragma once
/// @file
/// The cell_sim process's configuration (deploy/config/cell_sim.json), read with rigger::Config so
/// that every bad value is reported with the file, the JSON pointer and what was expected. No DDS.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rigger/base/config.hpp"
#include "rigger/cell_sim/settings.hpp"
#include "rigger/plc/plc_emulator.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/depth_noise.hpp"

namespace rigger::cell_sim {

/// Which wrench rigger/robot/wrench carries.
enum class WrenchSource {
  kExternal,  ///< the sensor reading minus the gripper's static weight (a controller with tool-load data)
  kRaw,       ///< what the sensor between flange and gripper reads, gripper weight included
};

/// Which renderer draws the camera's images (camera_renderers.hpp).
enum class CameraRendererKind {
  kAuto,    ///< kRaster for boxes through an undistorted lens, kMujoco otherwise (resolve_renderer)
  kMujoco,  ///< MuJoCo's OpenGL renderer through EGL: everything the physics holds, distortion, depth
  kRaster,  ///< the rasteriser of the cell file's boxes and markers: no meshes, no distortion, no depth
};

/// Rates are in simulated time: at a real-time factor of 1 they are wall-clock rates.
struct CellSimConfig {
  /// The cell description (crane limits, geometry, camera); deploy/cell/simulated_cell.json.
  std::filesystem::path cell_file;
  /// The MJCF; empty: the model shipped with the physics library.
  std::filesystem::path model_file;

  /// Simulated seconds per wall second; 0: as fast as possible (unpaced). Keep 1 with a crane
  /// gateway attached: the PLC's heartbeat watchdog runs on simulated time, as the crane does.
  double real_time_factor = 1.0;
  /// When the physics falls behind its schedule by more than this, it skips ahead (the simulation
  /// then runs slower than requested) instead of catching up in a burst.
  std::chrono::milliseconds max_lag{100};
  /// SCHED_FIFO priority of the physics thread (1..99); 0 keeps the normal scheduler.
  int realtime_priority = 0;

  // --- robot driver
  double wrench_rate_hz = 1000.0;
  WrenchSource wrench_source = WrenchSource::kExternal;
  double robot_state_rate_hz = 100.0;
  double gripper_state_rate_hz = 10.0;
  /// Longest timeout a twist command may ask for (its timeout_s is capped to this).
  std::chrono::milliseconds max_twist_timeout{500};
  /// How far a command's stamp may lie ahead of our clock (clock skew between hosts).
  std::chrono::milliseconds max_command_future{50};
  /// Motion commands older than this on receipt are refused (a burst after a network drop).
  std::chrono::milliseconds max_motion_command_age{1000};
  sim::CellPhysicsOptions physics;  ///< noise, seed, model path, twist backstop

  // --- crane PLC emulator
  plc::PlcEmulatorConfig plc;  ///< limits come from the cell file's crane entity
  std::string crane_id = "crane";
  std::chrono::milliseconds plc_scan_period{4};
  /// Start with the Modbus server listening (false: the link is "cut" until SIM_PLC_LINK on).
  bool plc_link_up = true;

  // --- camera
  bool camera_enabled = true;
  CameraRendererKind camera_renderer = CameraRendererKind::kAuto;
  std::string camera_id = "camera";
  /// Frames per simulated second; unset: the cell file's rate_hz.
  std::optional<double> camera_rate_hz;
  /// Image size; 0: the cell file's. Intrinsics scale with it.
  int camera_width_px = 0;
  int camera_height_px = 0;
  /// Pixel noise in grey levels; unset: the cell file's noise_stddev.
  std::optional<double> camera_noise_stddev;
  double camera_blur_sigma_px = 0.0;
  /// Where the simulated camera really is, in the optical frame the cell file gives it: the true pose
  /// is the file's times this (identity: exactly where the file says). The tracker is not told.
  Eigen::Isometry3d camera_pose_error = Eigen::Isometry3d::Identity();
  sim::DepthNoiseSettings camera_depth_noise;  ///< the depth image's (the MuJoCo renderer's only)

  // --- ROS 2 drivers (optional): the simulated robot's wrench, joint states and twist input and the camera's
  // images on a ROS 2 driver's topics (rt/…, ROS 2 types and QoS) instead of rigger's, for running the cell
  // behind services/ros2_bridge. Motions and the gripper stay on rigger's topics.
  struct Ros2Driver {
    std::string wrench_dds_topic;  ///< geometry_msgs/WrenchStamped written (sensor_data)
    std::string joint_states_dds_topic;  ///< sensor_msgs/JointState written (system_default QoS)
    /// The arm's joint names on joint_states, base to flange (the iiwa's A1..A7).
    std::vector<std::string> joint_names{"joint_a1", "joint_a2", "joint_a3", "joint_a4",
                                         "joint_a5", "joint_a6", "joint_a7"};
    std::string twist_dds_topic;   ///< geometry_msgs/TwistStamped read (reliable, as MoveIt Servo)
    std::string image_dds_topic;   ///< sensor_msgs/Image mono8 written (sensor_data)
    std::string camera_info_dds_topic;  ///< sensor_msgs/CameraInfo written with each image (sensor_data)
    std::string base_frame = "base_link";  ///< the twist's frame_id that means the robot base
    std::chrono::milliseconds twist_timeout{100};  ///< how long one TwistStamped drives (Servo's command timeout)
  };
  std::optional<Ros2Driver> ros2_driver;

  // --- tests and benchmarks
  double ground_truth_rate_hz = 50.0;
  double status_rate_hz = 100.0;
};

/// Reads cell_sim_settings() from `config`; paths are found by the rule of rigger/base/install.hpp (beside
/// the configuration file, then in the data folder). Does not call finish(). Loads the cell file's crane
/// limits. `cell_file`, when not empty, replaces the configuration's `cell_file` (the --cell option).
/// @throws ConfigError naming the file, the key and what was expected.
CellSimConfig read_cell_sim_config(const Config& config, const std::filesystem::path& cell_file = {});

/// The cell file used without a configuration: deploy/cell/simulated_cell.json in the installation's
/// data folder (rigger/base/install.hpp).
std::filesystem::path default_cell_file();

/// Steps of `timestep` between two publications at `rate_hz` (at least 1).
std::uint64_t steps_per_period(double rate_hz, std::chrono::nanoseconds timestep);

}  // namespace rigger::cell_sim
