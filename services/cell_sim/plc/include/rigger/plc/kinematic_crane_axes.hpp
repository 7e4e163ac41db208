#pragma once
// An ideal crane for tests and for running without physics: the drives follow the commanded
// velocity exactly and the positions integrate it.

#include <chrono>
#include <mutex>

#include "rigger/plc/crane_axes_io.hpp"

namespace rigger::plc {

/// Ideal drives: velocity = last command, position += velocity * dt on advance().
/// Thread-safe (one mutex), so tests may read it while the PLC thread drives it.
class KinematicCraneAxes final : public CraneAxesIo {
 public:
  /// Starts at rest at `position_m` carrying `load_kg`.
  explicit KinematicCraneAxes(const Eigen::Vector3d& position_m = Eigen::Vector3d::Zero(),
                              double load_kg = 0.0);

  void apply_velocity(const Eigen::Vector3d& velocity_mps) override;
  CraneAxesMeasurement read() const override;

  /// Integrates the positions over `dt` with the last commanded velocity.
  void advance(std::chrono::nanoseconds dt);
  /// Sets the hook load [kg] (to provoke an overload in tests).
  void set_load_kg(double load_kg);

 private:
  mutable std::mutex mutex_;
  CraneAxesMeasurement state_;
};

}  // namespace rigger::plc
