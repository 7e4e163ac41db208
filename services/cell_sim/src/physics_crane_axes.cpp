#include "physics_crane_axes.hpp"

namespace rigger::cell_sim {

plc::CraneAxesMeasurement to_plc_axes(const sim::CraneState& crane, double rail_height_m) {
  plc::CraneAxesMeasurement m;
  m.position_m = {crane.position_m.x(), crane.position_m.y(), rail_height_m - crane.position_m.z()};
  m.velocity_mps = {crane.velocity_mps.x(), crane.velocity_mps.y(), -crane.velocity_mps.z()};
  m.load_kg = crane.load_mass_estimate_kg;
  return m;
}

Eigen::Vector3d to_physics_setpoint(const Eigen::Vector3d& plc_velocity_mps) {
  return {plc_velocity_mps.x(), plc_velocity_mps.y(), -plc_velocity_mps.z()};
}

void PhysicsCraneAxes::apply_velocity(const Eigen::Vector3d& velocity_mps) {
  if (!physics_->set_crane_velocity(to_physics_setpoint(velocity_mps)).ok()) ++rejected_;
}

plc::CraneAxesMeasurement PhysicsCraneAxes::read() const {
  return to_plc_axes(physics_->crane_state(), physics_->geometry().crane.rail_height_m);
}

}  // namespace rigger::cell_sim
