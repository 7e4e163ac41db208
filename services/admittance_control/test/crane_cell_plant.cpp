#include "crane_cell_plant.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control_config.hpp"
#include "rigger/cell_config/cell_cad.hpp"

namespace rigger::control::test {
namespace {

const Eigen::Vector3d kGravity(0.0, 0.0, -9.81);

const nlohmann::json& entity(const nlohmann::json& cell, const std::string& id) {
  for (const auto& e : cell.at("entities"))
    if (e.at("id") == id) return e;
  throw std::runtime_error("simulated_cell.json has no entity " + id);
}

}  // namespace

CraneCellPlantConfig simulated_cell_plant_config(double load_yaw_deg) {
  const std::string path = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  const nlohmann::json cell = nlohmann::json::parse(in);
  const nlohmann::json& load = entity(cell, "load");
  const nlohmann::json& target = entity(cell, "target");
  const nlohmann::json& crane = entity(cell, "crane");
  CraneCellPlantConfig c;
  c.load_mass_kg = load.at("model").at("mass_kg").get<double>();
  c.rail_height_m = crane.at("attributes").at("rail_height_m").get<double>();
  c.pose_world_load = pose_from_config_json(load.at("pose"), path, "/load/pose");
  c.pose_world_load.linear() =
      Eigen::AngleAxisd(load_yaw_deg * kPi / 180.0, Eigen::Vector3d::UnitZ()) * c.pose_world_load.linear();
  c.pose_world_target = pose_from_config_json(target.at("pose"), path, "/target/pose");
  // The load's features as the world model serves them: derived from the STEP models (rigger_cell_cad).
  const cell::CellFile derived = cell::load_cell_file_with_cad(path);
  const cell::CadFeatures& features = derived.require("load", "the plant").features;
  c.pose_load_tcp = features.grasp_frames.at(0).pose_entity_feature;
  c.rope_attachment_load_m = features.rope_attachment.value().translation();
  c.pose_target_load_insertion = features.insertion.value().pose_target_entity;
  const auto accel = crane.at("attributes").at("max_accel_mps2").get<std::vector<double>>();
  c.crane_max_acceleration_mps2 = Eigen::Vector3d(accel.at(0), accel.at(1), accel.at(2));
  return c;
}

CraneCellPlant::CraneCellPlant(const CraneCellPlantConfig& config, unsigned seed)
    : config_(config), random_(seed), tcp_(config.pose_world_load * config.pose_load_tcp) {
  // The hook hangs straight above the attachment and the rope is pre-stretched by the load's weight.
  const Eigen::Vector3d attachment = config_.pose_world_load * config_.rope_attachment_load_m;
  const double rope_m = config_.rail_height_m - attachment.z();
  hook_xy_and_rope_ = Eigen::Vector3d(attachment.x(), attachment.y(),
                                      rope_m - config_.load_mass_kg * 9.81 / config_.rope_stiffness_n_per_m);
  update_contact(0.0, Eigen::Vector3d::Zero());
}

Eigen::Vector3d CraneCellPlant::rope_offset_world() const {
  const Eigen::Vector3d attachment = pose_world_load() * config_.rope_attachment_load_m;
  return Eigen::Vector3d(attachment.x() - hook_xy_and_rope_.x(), attachment.y() - hook_xy_and_rope_.y(), 0.0);
}

void CraneCellPlant::step(double dt_s, const Twist& tcp_twist_world, const Eigen::Vector3d& crane_velocity_world_mps,
                          const Eigen::Vector3d& push_on_load_world_n) {
  tcp_.translation() += tcp_twist_world.linear_mps * dt_s;
  const Eigen::Vector3d w = tcp_twist_world.angular_radps;
  if (w.norm() > 0.0)
    tcp_.linear() =
        (Eigen::AngleAxisd(w.norm() * dt_s, w.normalized()) * Eigen::Quaterniond(tcp_.linear())).normalized().toRotationMatrix();

  // The drives follow their setpoints with a lag, within the PLC's acceleration limits.
  Eigen::Vector3d dv = (crane_velocity_world_mps - crane_velocity_) * -std::expm1(-dt_s / config_.crane_time_constant_s);
  for (int i = 0; i < 3; ++i) {
    const double max_dv = config_.crane_max_acceleration_mps2[i] * dt_s;
    dv[i] = std::clamp(dv[i], -max_dv, max_dv);
  }
  crane_velocity_ += dv;
  hook_xy_and_rope_.x() += crane_velocity_.x() * dt_s;
  hook_xy_and_rope_.y() += crane_velocity_.y() * dt_s;
  hook_xy_and_rope_.z() -= crane_velocity_.z() * dt_s;  // hoisting up shortens the rope
  time_s_ += dt_s;
  update_contact(dt_s, push_on_load_world_n);

  if (time_s_ + 1e-9 >= next_capture_s_) {
    in_flight_.push_back(Frame{time_s_, noisy(pose_world_load()), noisy(config_.pose_world_target)});
    next_capture_s_ += 1.0 / config_.camera_rate_hz;
  }
  while (!in_flight_.empty() && in_flight_.front().capture_time_s + config_.camera_latency_s <= time_s_ + 1e-9) {
    delivered_ = in_flight_.front();
    in_flight_.pop_front();
  }
}

void CraneCellPlant::update_contact(double dt_s, const Eigen::Vector3d& push_on_load_world_n) {
  const Eigen::Isometry3d load = pose_world_load();
  const Eigen::Vector3d p_load = load.translation();
  const Eigen::Vector3d p_tcp = tcp_.translation();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  if (dt_s > 0.0) {
    // Velocity and acceleration of the load's centre from its motion (the robot is kinematic).
    const Eigen::Vector3d velocity = (p_load - previous_load_position_) / dt_s;
    acceleration = (velocity - load_velocity_) / dt_s;
    load_velocity_ = velocity;
  }
  previous_load_position_ = p_load;

  const Eigen::Vector3d attachment = load * config_.rope_attachment_load_m;
  const Eigen::Vector3d hook(hook_xy_and_rope_.x(), hook_xy_and_rope_.y(), config_.rail_height_m);
  const Eigen::Vector3d to_hook = hook - attachment;
  const double stretch = to_hook.norm() - hook_xy_and_rope_.z();
  const Eigen::Vector3d rope_force = config_.rope_stiffness_n_per_m * std::max(stretch, 0.0) * to_hook.normalized();

  // Newton-Euler for the load (rotational inertia neglected): what the robot must apply, and its
  // reaction on the robot.
  const double m = config_.load_mass_kg;
  const Eigen::Vector3d robot_on_load = m * acceleration - rope_force - m * kGravity - push_on_load_world_n;
  const Eigen::Vector3d robot_torque_on_load = (p_load - p_tcp).cross(m * (acceleration - kGravity)) -
                                               (attachment - p_tcp).cross(rope_force) -
                                               (p_load - p_tcp).cross(push_on_load_world_n);
  force_on_robot_world_ = -robot_on_load;
  torque_on_robot_world_ = -robot_torque_on_load;
}

WrenchSample CraneCellPlant::wrench_sample() {
  const Eigen::Matrix3d R = tcp_.linear();
  const Eigen::Vector3d sensor_to_tcp_world = R * config_.tcp_in_sensor_m;
  const Eigen::Vector3d torque_about_sensor_world =
      torque_on_robot_world_ + sensor_to_tcp_world.cross(force_on_robot_world_);
  const Eigen::Vector3d weight_sensor = R.transpose() * (config_.tool.mass_kg * kGravity);
  WrenchSample s;
  s.wrench_sensor.force_n = R.transpose() * force_on_robot_world_ + weight_sensor;
  s.wrench_sensor.torque_nm =
      R.transpose() * torque_about_sensor_world + config_.tool.center_of_mass_m.cross(weight_sensor);
  for (int i = 0; i < 3; ++i) {
    s.wrench_sensor.force_n[i] += config_.force_noise_n * unit_normal_(random_);
    s.wrench_sensor.torque_nm[i] += config_.torque_noise_nm * unit_normal_(random_);
  }
  s.age = Seconds(0.001);
  return s;
}

Eigen::Isometry3d CraneCellPlant::noisy(const Eigen::Isometry3d& pose) {
  Eigen::Isometry3d out = pose;
  Eigen::Vector3d dp, dr;
  for (int i = 0; i < 3; ++i) {
    dp[i] = config_.pose_noise_m * unit_normal_(random_);
    dr[i] = config_.pose_noise_rad * unit_normal_(random_);
  }
  out.translation() += dp;
  if (dr.norm() > 0.0) out.linear() = Eigen::AngleAxisd(dr.norm(), dr.normalized()).toRotationMatrix() * pose.linear();
  return out;
}

std::optional<std::pair<TrackedPose, TrackedPose>> CraneCellPlant::take_observation() {
  if (!delivered_) return std::nullopt;
  const Seconds age(time_s_ - delivered_->capture_time_s);
  std::pair<TrackedPose, TrackedPose> out{TrackedPose{delivered_->load, 0.9, age},
                                          TrackedPose{delivered_->target, 0.9, age}};
  delivered_.reset();
  return out;
}

}  // namespace rigger::control::test
