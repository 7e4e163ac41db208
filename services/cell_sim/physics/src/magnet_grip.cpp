#include "rigger/sim/magnet_grip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rigger::sim {

double magnet_utilisation(const Eigen::Vector3d& force_on_load_tool_n,
                          const Eigen::Vector3d& torque_on_load_tool_nm,
                          const MagnetCapacity& capacity) {
  const double pull = std::max(0.0, -force_on_load_tool_n.z());
  const double shear = force_on_load_tool_n.head<2>().norm();
  const double peel = torque_on_load_tool_nm.head<2>().norm();
  const double twist = std::abs(torque_on_load_tool_nm.z());
  const double demand_scale = pull + shear + peel + twist;
  const double holding = std::max(0.0, capacity.holding_force_n);
  if (holding <= 0.0) {
    return demand_scale > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  }
  return pull / holding + shear / (capacity.shear_friction * holding) +
         peel / (capacity.peel_lever_m * holding) +
         twist / (capacity.shear_friction * capacity.twist_lever_m * holding);
}

MagnetGripLogic::MagnetGripLogic(double filter_time_constant_s)
    : filter_time_constant_s_(std::max(0.0, filter_time_constant_s)) {}

void MagnetGripLogic::set_energized(bool energized) {
  if (energized == energized_) {
    return;
  }
  energized_ = energized;
  if (!energized) {
    release_pending_ = phase_ == GripperPhase::Holding;
    phase_ = GripperPhase::Off;
    filtered_utilisation_ = 0.0;
  } else {
    phase_ = GripperPhase::Searching;
  }
}

GripAction MagnetGripLogic::update(bool aligned_contact, double utilisation, double dt_s) {
  if (release_pending_) {
    release_pending_ = false;
    return GripAction::Release;
  }
  switch (phase_) {
    case GripperPhase::Off:
      return GripAction::None;
    case GripperPhase::Searching:
      if (aligned_contact) {
        phase_ = GripperPhase::Holding;
        filtered_utilisation_ = 0.0;
        return GripAction::Attach;
      }
      return GripAction::None;
    case GripperPhase::Holding: {
      const double u = std::isfinite(utilisation) ? std::max(0.0, utilisation) : 1e9;
      const double alpha =
          filter_time_constant_s_ > 0.0 ? std::min(1.0, dt_s / filter_time_constant_s_) : 1.0;
      filtered_utilisation_ += alpha * (u - filtered_utilisation_);
      if (filtered_utilisation_ >= 1.0) {
        phase_ = GripperPhase::Slipped;
        ++slip_count_;
        return GripAction::Release;
      }
      return GripAction::None;
    }
    case GripperPhase::Slipped:
      // A slipped load is still touching and moving; grip again only once it has come away.
      if (!aligned_contact) {
        phase_ = GripperPhase::Searching;
        filtered_utilisation_ = 0.0;
      }
      return GripAction::None;
  }
  return GripAction::None;
}

}  // namespace rigger::sim
