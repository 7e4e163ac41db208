#include "monitor_filters.hpp"

#include <cmath>

namespace rigger::monitor {

double time_constant_s(double cutoff_hz) { return 1.0 / (2.0 * 3.14159265358979323846 * cutoff_hz); }

const Eigen::Vector3d& LowPass3::update(const Eigen::Vector3d& x, double dt_s) {
  if (!initialized_) {
    // Starting at the first sample rather than at zero: a monitor armed under a static load must not
    // see a start-up transient.
    y_ = x;
    x_previous_ = x;
    initialized_ = true;
    return y_;
  }
  const double u = dt_s / tau_s_;
  const double one_minus_a = -std::expm1(-u);
  const double a = 1.0 - one_minus_a;
  // b = 1 − (1 − a)/u loses every digit to cancellation for tiny u; its series is u/2 − u²/6 + u³/24.
  const double b = u < 1e-4 ? u / 2.0 - u * u / 6.0 + u * u * u / 24.0 : 1.0 - one_minus_a / u;
  y_ = a * y_ + one_minus_a * x_previous_ + b * (x - x_previous_);
  x_previous_ = x;
  return y_;
}

void YankEstimator::reset() {
  force_.reset();
  yank_.reset();
}

const Eigen::Vector3d& YankEstimator::update(const Eigen::Vector3d& force_n, double dt_s) {
  const bool first = !force_.initialized();
  const Eigen::Vector3d& filtered = force_.update(force_n, dt_s);
  // The first stage's exact derivative at this sample, from y' = (x − y)/τ.
  const Eigen::Vector3d derivative = first ? Eigen::Vector3d::Zero() : Eigen::Vector3d((force_n - filtered) / force_.time_constant());
  return yank_.update(derivative, dt_s);
}

}  // namespace rigger::monitor
