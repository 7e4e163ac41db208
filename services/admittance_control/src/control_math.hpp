#pragma once
/// @file
/// Numerical building blocks of the control laws: the exact (zero-order-hold) discretisation of a
/// mass-damper-spring axis, a first-order low-pass, a continuous deadband, direction-preserving
/// saturation and acceleration (rate) limiting, and a smooth blend between two gain sets.
/// Pure functions and small value types; not thread-safe only in the sense that values are not shared.

#include <cmath>

#include <Eigen/Core>

#include "control_types.hpp"

namespace rigger::control {

/// pi, as a constant (M_PI is not standard C++).
inline constexpr double kPi = 3.14159265358979323846;

/// True when a sample of this age may be used: |age| <= max_age. A stamp far in the future is as
/// untrustworthy as an old one (the clocks disagree), and a NaN age is never fresh.
inline bool is_fresh(Seconds age, Seconds max_age) { return std::abs(age.count()) <= max_age.count(); }

/// One axis of M*a + D*v + K*x = f discretised exactly for a force held constant over the step
/// (zero-order hold): [x; v](k+1) = phi * [x; v](k) + gamma * f(k). Unconditionally stable for
/// M > 0, D > 0, K >= 0, and exact at the sample instants for a piecewise-constant force.
struct AxisDiscretisation {
  Eigen::Matrix2d phi = Eigen::Matrix2d::Identity();
  Eigen::Vector2d gamma = Eigen::Vector2d::Zero();
};

/// Discretises one axis. mass > 0 (kg or kg m^2), damping >= 0, stiffness >= 0, dt_s > 0.
/// Computed as the matrix exponential of the 3x3 augmented system [[A, B], [0, 0]] * dt, which is
/// well conditioned for every K >= 0 including K = 0 (where A is singular).
AxisDiscretisation discretise_axis(double mass, double damping, double stiffness, double dt_s);

/// Caches discretise_axis() for one axis: recomputes only when a parameter changes, so a steady
/// loop at a constant rate pays for the matrix exponential once.
class CachedAxisDiscretisation {
 public:
  /// The discretisation for these parameters (see discretise_axis()).
  const AxisDiscretisation& get(double mass, double damping, double stiffness, double dt_s);

 private:
  double mass_ = -1.0;
  double damping_ = -1.0;
  double stiffness_ = -1.0;
  double dt_s_ = -1.0;
  AxisDiscretisation value_;
};

/// Smoothing factor of a first-order low-pass y += alpha * (u - y) with cut-off `cutoff_hz`, exact
/// for a step input: alpha = 1 - exp(-2 pi fc dt). cutoff_hz <= 0 disables the filter (alpha = 1).
double low_pass_alpha(double cutoff_hz, double dt_s);

/// Continuous deadband: 0 inside [-width, width], value - sign(value) * width outside, so the output
/// has no jump at the threshold.
double apply_deadband(double value, double width);

/// Scales `vector` uniformly (its direction is kept) so that |v_i| <= max_per_axis_i for every axis
/// and |v| <= max_norm (max_norm <= 0 means no norm limit). An axis whose limit is <= 0 is locked
/// (its component set to zero) before the scaling. A vector within 1e-9 (relative) of a limit is
/// left as it is. Returns true when it changed the vector.
bool limit_preserving_direction(Eigen::Vector3d& vector, const Eigen::Vector3d& max_per_axis,
                                double max_norm = 0.0);

/// Moves `previous` towards `target` by at most max_rate_i * dt_s per axis, keeping the direction of
/// the change (uniform scaling of the step). Returns true when it limited.
bool limit_rate(const Eigen::Vector3d& previous, Eigen::Vector3d& target, const Eigen::Vector3d& max_rate,
                double dt_s);

/// Clamps each component to [-max_i, max_i] independently (for independent drives, such as a
/// crane's bridge, trolley and hoist). Returns true when it changed the vector.
bool clamp_per_axis(Eigen::Vector3d& vector, const Eigen::Vector3d& max_per_axis);

/// Moves each component of `previous` towards `target` by at most max_rate_i * dt_s, independently.
/// Returns true when it limited.
bool clamp_rate_per_axis(const Eigen::Vector3d& previous, Eigen::Vector3d& target, const Eigen::Vector3d& max_rate,
                         double dt_s);

/// Brings `velocity` towards zero by at most max_rate_i * dt_s per axis (direction kept). Returns
/// true while it is not zero yet.
bool ramp_to_zero(Eigen::Vector3d& velocity, const Eigen::Vector3d& max_rate, double dt_s);

/// 3 s^2 - 2 s^3 on [0, 1] (clamped): a blend weight whose slope is zero at both ends, so a gain
/// change starts and ends without a jump in the rate of change of the output.
double smoothstep(double s);

/// A blend of gain sets (any Eigen vector or matrix type G) from `from` to `to` over `duration`,
/// with a smoothstep weight. A new target restarts the blend from the current value, so a second
/// change during a blend does not jump either.
template <typename G>
class GainBlend {
 public:
  explicit GainBlend(const G& initial) : from_(initial), to_(initial), current_(initial) {}

  /// Starts blending from the current value to `target` over `duration` (zero: applied at once).
  void set_target(const G& target, Seconds duration) {
    from_ = current_;
    to_ = target;
    duration_ = duration;
    elapsed_ = Seconds(0.0);
    if (duration_.count() <= 0.0) current_ = to_;
  }
  /// Advances the blend by dt and returns the current value.
  const G& advance(Seconds dt) {
    if (!blending()) return current_;
    elapsed_ += dt;
    const double w = smoothstep(elapsed_.count() / duration_.count());
    current_ = from_ + (to_ - from_) * w;
    if (elapsed_ >= duration_) current_ = to_;
    return current_;
  }
  /// The value in effect now.
  const G& current() const { return current_; }
  /// The value being blended to.
  const G& target() const { return to_; }
  /// True while the current value is not yet the target.
  bool blending() const { return duration_.count() > 0.0 && elapsed_ < duration_; }

 private:
  G from_;
  G to_;
  G current_;
  Seconds duration_{0.0};
  Seconds elapsed_{0.0};
};

}  // namespace rigger::control
