#pragma once
// The magnetic gripper's logic, apart from the physics: how much of its holding capacity a load
// uses, and when it grips, slips and lets go.  Pure C++.

#include <Eigen/Core>

#include "rigger/sim/physics_types.hpp"

namespace rigger::sim {

/// Holding capacity of a magnet plate.  A magnet holds best against a straight pull; sideways
/// (shear) it holds by friction, and a moment peels it off from one edge.
struct MagnetCapacity {
  double holding_force_n = 1200.0;  ///< rated pull-off force, normal to the face
  double shear_friction = 0.5;      ///< shear capacity = friction * holding force
  double peel_lever_m = 0.05;       ///< moment capacity about a face axis = holding force * lever
  double twist_lever_m = 0.04;      ///< twist capacity = friction * holding force * lever
};

/// Share of the capacity a load uses (0 = unloaded, >= 1 = beyond capacity), as a linear
/// interaction of pull, shear, peel and twist.  Inputs are what the magnet exerts on the load, in
/// the tool frame (z out of the face into the load), torque about the face centre: pulling the
/// load towards the face is a force along -z.  A push (+z) is carried by the face contact and
/// uses no capacity.  A capacity of zero makes any load infinite utilisation.
double magnet_utilisation(const Eigen::Vector3d& force_on_load_tool_n,
                          const Eigen::Vector3d& torque_on_load_tool_nm,
                          const MagnetCapacity& capacity);

/// What the gripper should do after an update.
enum class GripAction { None, Attach, Release };

/// Gripper state machine: Off -> (energize) Searching -> (flat contact) Holding -> (overload)
/// Slipped -> (face leaves the load) Searching; de-energizing releases from any phase.
/// The overload test uses the utilisation low-pass filtered over `filter_time_constant_s`, so a
/// one-step spike of the contact solver does not drop the load.  Not thread-safe.
class MagnetGripLogic {
 public:
  explicit MagnetGripLogic(double filter_time_constant_s = 0.005);

  /// Energize or de-energize; de-energizing while holding asks for Release on the next update.
  void set_energized(bool energized);

  /// One control step: `aligned_contact` = the face is flat on the load; `utilisation` = the
  /// current unfiltered utilisation (ignored unless holding); dt in seconds.
  GripAction update(bool aligned_contact, double utilisation, double dt_s);

  [[nodiscard]] GripperPhase phase() const { return phase_; }
  [[nodiscard]] bool energized() const { return energized_; }
  [[nodiscard]] double filtered_utilisation() const { return filtered_utilisation_; }
  [[nodiscard]] std::uint64_t slip_count() const { return slip_count_; }

 private:
  double filter_time_constant_s_;
  bool energized_ = false;
  bool release_pending_ = false;
  GripperPhase phase_ = GripperPhase::Off;
  double filtered_utilisation_ = 0.0;
  std::uint64_t slip_count_ = 0;
};

}  // namespace rigger::sim
