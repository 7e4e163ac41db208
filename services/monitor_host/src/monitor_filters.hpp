#pragma once
/// @file
/// Filters for irregularly sampled 3-vectors (force samples whose spacing jitters).
///
/// LowPass3 is the first-order low-pass y' = (x − y)/τ with τ = 1/(2π f_c), discretised exactly for an
/// input that is linear between samples (first-order hold):
///   a = e^(−h/τ),  b = 1 − τ(1 − a)/h,
///   y_k = a·y_(k−1) + (1 − a)·x_(k−1) + b·(x_k − x_(k−1)).
/// At the sample times this equals the continuous filter's output for every piecewise-linear input,
/// whatever the spacing h, so a ramp is tracked with exactly the lag τ and a step applied between two
/// samples behaves like the continuous step delayed by half that interval. Both weights are positive,
/// so it is a true averaging filter for any h > 0.
///
/// YankEstimator differentiates force with the critically damped filtered differentiator
///   H(s) = s / (τs + 1)²:
/// stage 1 is LowPass3 on the force; its exact derivative at a sample is (x_k − y_k)/τ (from the
/// filter's own equation, so no finite difference and no half-sample lag); stage 2 is LowPass3 on that
/// derivative. For white force noise of σ per axis sampled every T seconds, the yank noise per axis is
///   σ_yank ≈ σ·√(T / (4τ³))
/// (e.g. σ = 2 N, T = 1 ms, f_c = 10 Hz: ≈ 15.8 N/s), against ≈ σ·√2/T (≈ 2800 N/s) for a raw backward
/// difference. A force ramp of slope r gives a yank r·(1 − e^(−t/τ)(1 + t/τ)), i.e. it reaches r with a
/// delay of about 2τ; a step S gives a yank pulse (S/τ)(t/τ)e^(−t/τ) peaking at S/(e·τ) after τ.

#include <Eigen/Core>

namespace rigger::monitor {

/// The time constant τ = 1/(2π f_c) of a first-order filter with cut-off `cutoff_hz`.
double time_constant_s(double cutoff_hz);

/// First-order low-pass on a 3-vector with first-order-hold discretisation (see file comment).
class LowPass3 {
 public:
  /// @param time_constant_s τ > 0.
  explicit LowPass3(double time_constant_s = 1.0) : tau_s_(time_constant_s) {}

  /// Forgets the state; the next update initialises the output to its input.
  void reset() { initialized_ = false; }
  /// Filters one sample taken `dt_s` > 0 after the previous one (ignored for the first sample).
  const Eigen::Vector3d& update(const Eigen::Vector3d& x, double dt_s);

  /// True once a sample has been filtered since construction or reset().
  bool initialized() const { return initialized_; }
  /// The filtered value after the last update.
  const Eigen::Vector3d& value() const { return y_; }
  /// τ in seconds.
  double time_constant() const { return tau_s_; }

 private:
  double tau_s_;
  bool initialized_ = false;
  Eigen::Vector3d y_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_previous_ = Eigen::Vector3d::Zero();
};

/// Yank (d/dt of force) through H(s) = s/(τs + 1)² (see file comment). Units: force in N, yank in N/s.
class YankEstimator {
 public:
  explicit YankEstimator(double time_constant_s = 1.0) : force_(time_constant_s), yank_(time_constant_s) {}

  /// Forgets the state; the next update starts from zero yank.
  void reset();
  /// One force sample `dt_s` > 0 after the previous one; returns the filtered yank vector.
  const Eigen::Vector3d& update(const Eigen::Vector3d& force_n, double dt_s);

  /// The yank after the last update, N/s.
  const Eigen::Vector3d& yank() const { return yank_.value(); }
  /// The first stage's low-passed force after the last update, N.
  const Eigen::Vector3d& filtered_force() const { return force_.value(); }

 private:
  LowPass3 force_;
  LowPass3 yank_;
};

}  // namespace rigger::monitor
