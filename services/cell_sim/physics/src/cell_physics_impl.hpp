#pragma once
// Internal: CellPhysics's state and its per-step parts, defined by job: cell_physics.cpp (the model, the
// step, the crane and the public interface), arm_servo.cpp (the arm's joint servo with its payload) and
// gripper_physics.cpp (the magnet and the wrist sensor).

#include <mujoco/mujoco.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "arm_controller.hpp"
#include "arm_kinematics.hpp"
#include "cell_model.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::sim {

inline Eigen::Vector3d vec3(const mjtNum* values) { return {values[0], values[1], values[2]}; }

inline void add_wrench_at(mjData& data, int body, const Eigen::Vector3d& force,
                          const Eigen::Vector3d& torque, const Eigen::Vector3d& point_world) {
  // xfrc_applied is (force, torque) at the body's centre of mass, world frame.
  const Eigen::Vector3d lever = point_world - vec3(data.xipos + 3 * body);
  const Eigen::Vector3d total_torque = torque + lever.cross(force);
  for (int i = 0; i < 3; ++i) {
    data.xfrc_applied[6 * body + i] += force[i];
    data.xfrc_applied[6 * body + 3 + i] += total_torque[i];
  }
}

struct CellPhysics::Impl {
  Impl(const CellGeometry& cell_geometry, const CellPhysicsOptions& physics_options);

  void substep();
  void control_crane(double dt_s);
  void control_arm(double dt_s);
  JointVector add_payload_inertia(const JointVector& joint_acceleration);
  void control_gripper(double dt_s);
  void record_wrench();
  int aligned_face_contact() const;
  MagnetSpring magnet_spring_for(int body) const;
  JointVector joint_positions() const;
  JointVector joint_velocities() const;
  Eigen::Isometry3d site_pose_world(int site) const;
  Eigen::Isometry3d body_pose_world(int body) const;
  double now_s() const { return static_cast<double>(steps) * timestep_s; }
  void run_steps(std::uint64_t count);

  CellGeometry cell;
  CellPhysicsOptions options;
  detail::ModelPtr model;
  detail::DataPtr data;
  detail::CellModelIndex index;
  ArmLimits arm_limits;
  std::unique_ptr<detail::ArmKinematics> kinematics;
  std::unique_ptr<detail::ArmController> arm;
  Eigen::Isometry3d pose_world_base = Eigen::Isometry3d::Identity();

  double timestep_s = 0.001;
  std::chrono::nanoseconds timestep_ns{1000000};
  std::uint64_t steps = 0;
  std::chrono::steady_clock::duration wall_stepping{0};

  // Crane.
  TravelDrive bridge;
  TravelDrive trolley;
  HoistDrum drum;
  bool crane_frozen = false;
  Eigen::Vector3d crane_setpoint_mps = Eigen::Vector3d::Zero();
  double rope_tension = 0.0;
  double load_mass_estimate = 0.0;
  double hook_mass_kg = 0.0;

  // Arm servo.
  JointVector joint_torque = JointVector::Zero();
  JointVector joint_model_damping = JointVector::Zero();  // the model's own joint damping (N m s/rad)
  std::vector<mjtNum> servo_acceleration;
  std::vector<mjtNum> servo_force;
  std::vector<mjtNum> payload_jacp;  // 3 x nv, row major: the gripper's Jacobian at the payload's centre of mass
  std::vector<mjtNum> payload_jacr;

  // Gripper.
  MagnetGripLogic magnet;
  MagnetCapacity capacity;
  bool holding = false;
  bool face_in_contact = false;
  int held_body = -1;  // the free object's body while holding
  double held_s = 0.0;  // how long the magnet has held it
  double utilisation = 0.0;
  Eigen::Vector3d anchor_load = Eigen::Vector3d::Zero();  // load frame
  Eigen::Matrix3d rotation_tool_load = Eigen::Matrix3d::Identity();

  Eigen::Vector3d load_force_world = Eigen::Vector3d::Zero();

  // Wrist sensor.
  Wrench wrench_raw;
  Wrench wrench_external;
  std::mt19937_64 noise_engine;
  std::normal_distribution<double> unit_normal{0.0, 1.0};
};

}  // namespace rigger::sim
