#include "rigger/sim/trapezoid_profile.hpp"

#include <algorithm>
#include <cmath>

namespace rigger::sim {

std::optional<TrapezoidProfile> TrapezoidProfile::plan(const Eigen::VectorXd& distances,
                                                       const Eigen::VectorXd& speed_limits,
                                                       const Eigen::VectorXd& accel_limits) {
  if (distances.size() != speed_limits.size() || distances.size() != accel_limits.size()) {
    return std::nullopt;
  }
  // The dimensions share s(t), so the binding ones set the pace: a dimension needs at least
  // |d|/v of cruise and |d|/a of "acceleration budget".  Taking the maxima turns the problem into
  // one unit-distance trapezoid with speed 1/V and acceleration 1/A, which every dimension then
  // respects by construction.
  double time_at_speed = 0.0;  // V = max |d_i| / v_i  (s)
  double accel_budget = 0.0;   // A = max |d_i| / a_i  (s^2)
  for (Eigen::Index i = 0; i < distances.size(); ++i) {
    const double distance = distances[i];
    const double speed = speed_limits[i];
    const double accel = accel_limits[i];
    if (!std::isfinite(distance) || !std::isfinite(speed) || !std::isfinite(accel) ||
        distance < 0.0 || speed <= 0.0 || accel <= 0.0) {
      return std::nullopt;
    }
    time_at_speed = std::max(time_at_speed, distance / speed);
    accel_budget = std::max(accel_budget, distance / accel);
  }

  TrapezoidProfile profile;
  if (time_at_speed <= 0.0 || accel_budget <= 0.0) {
    return profile;  // nothing moves
  }
  if (accel_budget >= time_at_speed * time_at_speed) {
    // Too short to reach the speed limit: triangular profile.
    profile.accel_time_s_ = std::sqrt(accel_budget);
    profile.duration_s_ = 2.0 * profile.accel_time_s_;
    profile.peak_rate_ = 1.0 / profile.accel_time_s_;
  } else {
    profile.accel_time_s_ = accel_budget / time_at_speed;
    profile.duration_s_ = time_at_speed + profile.accel_time_s_;
    profile.peak_rate_ = 1.0 / time_at_speed;
  }
  profile.accel_ = 1.0 / accel_budget;
  return profile;
}

TrapezoidProfile::Sample TrapezoidProfile::sample(double t_s) const {
  Sample result;
  if (duration_s_ <= 0.0 || t_s >= duration_s_) {
    result.s = 1.0;
    return result;
  }
  if (t_s <= 0.0) {
    return result;
  }
  if (t_s < accel_time_s_) {
    result.s = 0.5 * accel_ * t_s * t_s;
    result.ds = accel_ * t_s;
    result.dds = accel_;
  } else if (t_s <= duration_s_ - accel_time_s_) {
    result.s = 0.5 * accel_ * accel_time_s_ * accel_time_s_ + peak_rate_ * (t_s - accel_time_s_);
    result.ds = peak_rate_;
  } else {
    const double remaining = duration_s_ - t_s;
    result.s = 1.0 - 0.5 * accel_ * remaining * remaining;
    result.ds = accel_ * remaining;
    result.dds = -accel_;
  }
  return result;
}

}  // namespace rigger::sim
