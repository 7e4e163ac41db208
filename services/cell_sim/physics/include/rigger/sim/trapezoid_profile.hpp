#pragma once
// Time-optimal trapezoidal velocity profile shared by several dimensions that start and stop
// together (synchronized point-to-point motion in joint space or along a Cartesian path).

#include <Eigen/Core>
#include <optional>

namespace rigger::sim {

/// Normalized path parameter s(t), from 0 at t = 0 to 1 at t = duration: constant acceleration,
/// cruise, constant deceleration.  Immutable after planning; cheap to copy.
class TrapezoidProfile {
 public:
  struct Sample {
    double s = 0.0;    ///< path parameter, 0..1
    double ds = 0.0;   ///< ds/dt (1/s)
    double dds = 0.0;  ///< d2s/dt2 (1/s^2)
  };

  /// The fastest profile under which every dimension i, moving |distances[i]| * s(t), keeps its
  /// speed within speed_limits[i] and its acceleration within accel_limits[i].  nullopt when the
  /// sizes differ or a value is not finite, a distance negative or a limit not positive.
  static std::optional<TrapezoidProfile> plan(const Eigen::VectorXd& distances,
                                              const Eigen::VectorXd& speed_limits,
                                              const Eigen::VectorXd& accel_limits);

  /// Total time (s); 0 when every distance is 0.
  [[nodiscard]] double duration_s() const { return duration_s_; }

  /// s and its derivatives at time t (s); clamped to the ends outside [0, duration].
  [[nodiscard]] Sample sample(double t_s) const;

 private:
  double duration_s_ = 0.0;
  double accel_time_s_ = 0.0;
  double peak_rate_ = 0.0;  // 1/s
  double accel_ = 0.0;      // 1/s^2
};

}  // namespace rigger::sim
