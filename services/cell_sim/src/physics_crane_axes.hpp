#pragma once
/// @file
/// The crane drives of the MuJoCo physics as the PLC emulator sees them (plc::CraneAxesIo).
///
/// Units and frames differ on the two sides, and this adapter is the one place that converts:
///   PLC (Modbus map, crane frame): x bridge, y trolley, z = hook height above the crane frame, up
///                                  positive; hoist velocity up positive.
///   physics (sim::CraneState):     x bridge, y trolley, z = rope paid out by the drum, positive =
///                                  longer rope = hook lower.
///   z_plc = rail_height - z_physics,  v_plc = -v_physics.

#include <Eigen/Core>

#include "rigger/plc/crane_axes_io.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::cell_sim {

/// The PLC's view of a crane state: positions and velocities in the Modbus map's convention.
plc::CraneAxesMeasurement to_plc_axes(const sim::CraneState& crane, double rail_height_m);
/// A PLC drive command (z up positive) as the physics' setpoint (z = rope pay-out rate).
Eigen::Vector3d to_physics_setpoint(const Eigen::Vector3d& plc_velocity_mps);

/// Adapter from the PLC emulator to CellPhysics. Not thread-safe, like CellPhysics: the physics
/// thread steps both the PLC and the physics.
class PhysicsCraneAxes final : public plc::CraneAxesIo {
 public:
  explicit PhysicsCraneAxes(sim::CellPhysics& physics) : physics_(&physics) {}
  /// Points the adapter at another physics instance (after a simulation reset).
  void attach(sim::CellPhysics& physics) { physics_ = &physics; }

  void apply_velocity(const Eigen::Vector3d& velocity_mps) override;
  plc::CraneAxesMeasurement read() const override;

  /// Commands the physics refused (non-finite or absurd setpoints), for diagnostics.
  std::uint64_t rejected_commands() const { return rejected_; }

 private:
  sim::CellPhysics* physics_;
  std::uint64_t rejected_ = 0;
};

}  // namespace rigger::cell_sim
