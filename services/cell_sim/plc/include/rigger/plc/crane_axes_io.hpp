#pragma once
// The PLC's view of the crane's drives: what the physics (MuJoCo in cell_sim, a kinematic
// integrator in tests) must offer the PLC emulator.

#include <Eigen/Core>

namespace rigger::plc {

/// Measured state of the crane axes. Crane frame: x bridge, y trolley, z hook height (up).
struct CraneAxesMeasurement {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  double load_kg = 0.0;  ///< hook load as a load cell would weigh it (rope tension / g)
};

/// The crane drives as the PLC sees them. Implementations decide their own thread safety; the
/// PLC emulator calls both methods from the thread that runs PlcEmulator::step().
class CraneAxesIo {
 public:
  virtual ~CraneAxesIo() = default;
  /// Commands the axis drives' velocities [m/s], crane frame (x bridge, y trolley, z hook up).
  /// The PLC has already applied its speed, acceleration and limit-switch rules.
  virtual void apply_velocity(const Eigen::Vector3d& velocity_mps) = 0;
  /// The latest measurement.
  virtual CraneAxesMeasurement read() const = 0;
};

}  // namespace rigger::plc
