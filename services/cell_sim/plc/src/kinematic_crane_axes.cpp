#include "rigger/plc/kinematic_crane_axes.hpp"

namespace rigger::plc {

KinematicCraneAxes::KinematicCraneAxes(const Eigen::Vector3d& position_m, double load_kg) {
  state_.position_m = position_m;
  state_.load_kg = load_kg;
}

void KinematicCraneAxes::apply_velocity(const Eigen::Vector3d& velocity_mps) {
  const std::lock_guard<std::mutex> lock(mutex_);
  state_.velocity_mps = velocity_mps;
}

CraneAxesMeasurement KinematicCraneAxes::read() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

void KinematicCraneAxes::advance(std::chrono::nanoseconds dt) {
  const std::lock_guard<std::mutex> lock(mutex_);
  state_.position_m += state_.velocity_mps * std::chrono::duration<double>(dt).count();
}

void KinematicCraneAxes::set_load_kg(double load_kg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  state_.load_kg = load_kg;
}

}  // namespace rigger::plc
