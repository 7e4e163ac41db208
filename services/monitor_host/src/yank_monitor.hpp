#pragma once
/// @file
/// YankMonitor: fires YANK_LIMIT when the yank (time derivative of the wrist force) exceeds its
/// threshold: a slip, a collision, or a grasp that did not hold. The yank comes from the filtered
/// differentiator H(s) = s/(τs + 1)² of YankEstimator (monitor_filters.hpp), which handles irregular
/// sample spacing exactly for piecewise-linear force and keeps sensor noise low: σ_yank ≈ σ·√(T/(4τ³))
/// per axis. Choose the threshold well above that (≥ 8·σ_yank·√3 for the norm keeps a 60 s, 1 kHz
/// stream of Gaussian noise free of false alarms) and below the yank of the event to detect: a force
/// ramp of slope r reaches yank r·(1 − e^(−t/τ)(1 + t/τ)); a step S peaks at S/(e·τ).
///
/// Detection delay for a force ramp of slope r > threshold Y starting at t = 0: the first t with
/// 1 − e^(−t/τ)(1 + t/τ) > Y/r, quantised to the samples (within one sample period).

#include "monitor.hpp"
#include "monitor_filters.hpp"

namespace rigger::monitor {

class YankMonitor final : public Monitor {
 public:
  /// Name "YankMonitor"; parameters max_yank_n_per_s (required), axis, cutoff_hz, max_sample_age_s.
  static const MonitorDescription& describe();
  const MonitorDescription& description() const override { return describe(); }

  /// The filtered yank vector after the last sample, N/s (sensor frame).
  const Eigen::Vector3d& yank_n_per_s() const { return estimator_.yank(); }

 protected:
  std::vector<std::string> configure(const ParamValues& values) override;
  void start(Stamp start) override;
  Verdict sample(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm,
                 std::optional<double> dt_s) override;

 private:
  double max_yank_n_per_s_ = 0.0;
  Axis axis_ = Axis::kNorm;
  YankEstimator estimator_;
};

}  // namespace rigger::monitor
