#pragma once
/// @file
/// A small simulated plant for closed-loop tests of the control laws (the MuJoCo cell comes later):
/// a kinematic robot whose TCP follows the commanded twist exactly, a load rigidly grasped by it, an
/// overhead crane whose bridge, trolley and hoist follow their velocity commands through a
/// first-order drive lag with acceleration limits, and an elastic rope from the hook to the load's
/// rope attachment. The wrist sensor reads the wrench the load (rope, gravity, inertia, an optional
/// push) exerts on the robot, plus the tool's weight and noise. A camera observes load and target
/// poses at its frame rate, with latency and noise.

#include <deque>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "control_types.hpp"
#include "robot_admittance.hpp"
#include "visual_servo.hpp"

namespace rigger::control::test {

struct CraneCellPlantConfig {
  double load_mass_kg = 40.0;
  double rail_height_m = 4.5;  ///< height of the hook's rope drum (the trolley)
  Eigen::Isometry3d pose_world_load = Eigen::Isometry3d::Identity();    ///< initial
  Eigen::Isometry3d pose_world_target = Eigen::Isometry3d::Identity();  ///< static
  Eigen::Isometry3d pose_load_tcp = Eigen::Isometry3d::Identity();      ///< grasp frame
  Eigen::Vector3d rope_attachment_load_m{0.0, 0.0, 0.1};
  /// Not used by the plant: the load's insertion offset from the same cell file, for the servo.
  Eigen::Isometry3d pose_target_load_insertion = Eigen::Isometry3d::Identity();
  ToolModel tool{2.5, Eigen::Vector3d(0.0, 0.0, 0.06)};
  Eigen::Vector3d tcp_in_sensor_m{0.0, 0.0, 0.12};
  double rope_stiffness_n_per_m = 2.0e4;  ///< rope and sling elasticity
  double crane_time_constant_s = 0.1;     ///< drive response to a velocity command
  Eigen::Vector3d crane_max_acceleration_mps2{0.5, 0.5, 0.3};
  double force_noise_n = 0.3;
  double torque_noise_nm = 0.03;
  double camera_rate_hz = 30.0;
  double camera_latency_s = 0.03;
  double pose_noise_m = 0.0005;
  double pose_noise_rad = 0.1 * 3.14159265358979323846 / 180.0;
};

/// The cell of deploy/cell/simulated_cell.json: load, target, grasp frame and rope attachment as
/// given there (read by the test), with the load yawed by `load_yaw_deg` about its centre.
CraneCellPlantConfig simulated_cell_plant_config(double load_yaw_deg);

class CraneCellPlant {
 public:
  CraneCellPlant(const CraneCellPlantConfig& config, unsigned seed);

  /// Advances by dt: the TCP moves with `tcp_twist_world` (velocity of the TCP point, world axes), the
  /// crane drives towards `crane_velocity_world_mps` (x bridge, y trolley, z hoist up), and
  /// `push_on_load_world_n` acts at the load's centre.
  void step(double dt_s, const Twist& tcp_twist_world, const Eigen::Vector3d& crane_velocity_world_mps,
            const Eigen::Vector3d& push_on_load_world_n = Eigen::Vector3d::Zero());

  /// What the wrist sensor reads now (sensor frame, tool weight and noise included; age 1 ms).
  WrenchSample wrench_sample();
  /// The sensor's (and TCP's) orientation in the world (= robot base orientation).
  Eigen::Quaterniond orientation_world_sensor() const { return Eigen::Quaterniond(tcp_.linear()); }
  /// Ground truth.
  const Eigen::Isometry3d& pose_world_tcp() const { return tcp_; }
  Eigen::Isometry3d pose_world_load() const { return tcp_ * config_.pose_load_tcp.inverse(); }
  const Eigen::Isometry3d& pose_world_target() const { return config_.pose_world_target; }
  /// The contact force the load exerts on the robot, world frame, N (no noise, no tool).
  const Eigen::Vector3d& force_on_robot_world() const { return force_on_robot_world_; }
  /// The rope attachment minus the point below the hook, world frame, m.
  Eigen::Vector3d rope_offset_world() const;
  /// The crane's actual velocity, world frame.
  const Eigen::Vector3d& crane_velocity_world() const { return crane_velocity_; }
  double time_s() const { return time_s_; }

  /// The camera's newest delivered observation of (load, target), if one arrived since the last
  /// call; ages are relative to the current time.
  std::optional<std::pair<TrackedPose, TrackedPose>> take_observation();

 private:
  struct Frame {
    double capture_time_s;
    Eigen::Isometry3d load;
    Eigen::Isometry3d target;
  };

  void update_contact(double dt_s, const Eigen::Vector3d& push_on_load_world_n);
  Eigen::Isometry3d noisy(const Eigen::Isometry3d& pose);

  CraneCellPlantConfig config_;
  std::mt19937 random_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  double time_s_ = 0.0;
  Eigen::Isometry3d tcp_;
  Eigen::Vector3d hook_xy_and_rope_;  // trolley x, trolley y, unstretched rope length
  Eigen::Vector3d crane_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_load_position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d load_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_on_robot_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_on_robot_world_ = Eigen::Vector3d::Zero();  // about the TCP
  double next_capture_s_ = 0.0;
  std::deque<Frame> in_flight_;
  std::optional<Frame> delivered_;
};

}  // namespace rigger::control::test
