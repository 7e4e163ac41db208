#include "control_math.hpp"

#include <algorithm>
#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

namespace rigger::control {
namespace {

constexpr double kLimitRelativeTolerance = 1e-9;

// Applies `limit` to the change from `previous` to `target`; true when it limited.
template <typename Limit>
bool limit_step(const Eigen::Vector3d& previous, Eigen::Vector3d& target, Limit limit) {
  Eigen::Vector3d step = target - previous;
  if (!limit(step)) return false;
  target = previous + step;
  return true;
}

}  // namespace

AxisDiscretisation discretise_axis(double mass, double damping, double stiffness, double dt_s) {
  // Augmented state [x, v, f] with f constant over the step: the top rows of exp(Z * dt) hold both
  // the state transition phi and the zero-order-hold input vector gamma. Eigen's Pade
  // scaling-and-squaring exponential stays accurate where the closed forms lose precision
  // (K -> 0, critical damping).
  Eigen::Matrix3d z = Eigen::Matrix3d::Zero();
  z(0, 1) = 1.0;
  z(1, 0) = -stiffness / mass;
  z(1, 1) = -damping / mass;
  z(1, 2) = 1.0 / mass;
  const Eigen::Matrix3d e = (z * dt_s).exp();
  AxisDiscretisation out;
  out.phi = e.topLeftCorner<2, 2>();
  out.gamma = e.topRightCorner<2, 1>();
  return out;
}

const AxisDiscretisation& CachedAxisDiscretisation::get(double mass, double damping, double stiffness,
                                                        double dt_s) {
  if (mass != mass_ || damping != damping_ || stiffness != stiffness_ || dt_s != dt_s_) {
    value_ = discretise_axis(mass, damping, stiffness, dt_s);
    mass_ = mass;
    damping_ = damping;
    stiffness_ = stiffness;
    dt_s_ = dt_s;
  }
  return value_;
}

double low_pass_alpha(double cutoff_hz, double dt_s) {
  if (cutoff_hz <= 0.0) return 1.0;
  return -std::expm1(-2.0 * kPi * cutoff_hz * dt_s);
}

double apply_deadband(double value, double width) {
  if (value > width) return value - width;
  if (value < -width) return value + width;
  return 0.0;
}

bool limit_preserving_direction(Eigen::Vector3d& vector, const Eigen::Vector3d& max_per_axis, double max_norm) {
  // An axis whose limit is zero is locked: its component is removed first, otherwise the uniform
  // scaling below would stop the motion along every other axis as well.
  bool limited = false;
  for (int i = 0; i < 3; ++i) {
    if (max_per_axis[i] <= 0.0 && vector[i] != 0.0) {
      vector[i] = 0.0;
      limited = true;
    }
  }
  double scale = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double magnitude = std::abs(vector[i]);
    if (max_per_axis[i] > 0.0 && magnitude > max_per_axis[i]) scale = std::min(scale, max_per_axis[i] / magnitude);
  }
  const double norm = vector.norm();
  if (max_norm > 0.0 && norm > max_norm) scale = std::min(scale, max_norm / norm);
  // Within rounding of the limit counts as inside: scaling by 1 - 1e-16 would leave a remainder of
  // 1e-17 that takes one more cycle to clear.
  if (scale >= 1.0 - kLimitRelativeTolerance) return limited;
  vector *= scale;
  return true;
}

bool limit_rate(const Eigen::Vector3d& previous, Eigen::Vector3d& target, const Eigen::Vector3d& max_rate,
                double dt_s) {
  return limit_step(previous, target, [&](Eigen::Vector3d& step) {
    return limit_preserving_direction(step, max_rate * dt_s);
  });
}

bool clamp_per_axis(Eigen::Vector3d& vector, const Eigen::Vector3d& max_per_axis) {
  const Eigen::Vector3d clamped = vector.cwiseMin(max_per_axis).cwiseMax(-max_per_axis);
  const bool changed = clamped != vector;
  vector = clamped;
  return changed;
}

bool clamp_rate_per_axis(const Eigen::Vector3d& previous, Eigen::Vector3d& target, const Eigen::Vector3d& max_rate,
                         double dt_s) {
  return limit_step(previous, target, [&](Eigen::Vector3d& step) { return clamp_per_axis(step, max_rate * dt_s); });
}

bool ramp_to_zero(Eigen::Vector3d& velocity, const Eigen::Vector3d& max_rate, double dt_s) {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  limit_rate(velocity, target, max_rate, dt_s);
  velocity = target;
  return !velocity.isZero(0.0);
}

double smoothstep(double s) {
  const double c = std::clamp(s, 0.0, 1.0);
  return c * c * (3.0 - 2.0 * c);
}

}  // namespace rigger::control
