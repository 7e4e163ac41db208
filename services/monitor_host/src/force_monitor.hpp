#pragma once
/// @file
/// ForceMonitor: fires FORCE_LIMIT when the low-pass-filtered force (or torque) has stayed above its
/// limit for at least the dwell time. The magnitude is either the vector norm or the absolute value of
/// one sensor-frame axis. With `relative`, the limit applies to the change from the first sample after
/// the start (a tare), so a monitor armed while a load hangs on the tool watches only new contact.
///
/// Detection delay for a force step from below the limit to S above the tare (limit L < S), filter
/// time constant τ = 1/(2π cutoff_hz), dwell d: the filtered force crosses L at t_c = −τ·ln(1 − L/S) and
/// the monitor fires at t_c + d, quantised to the samples (within one sample period).

#include "monitor.hpp"
#include "monitor_filters.hpp"

namespace rigger::monitor {

class ForceMonitor final : public Monitor {
 public:
  /// Name "ForceMonitor"; parameters max_force_n, max_torque_nm (0 = not watched; at least one > 0),
  /// axis, dwell_s, cutoff_hz, relative, max_sample_age_s.
  static const MonitorDescription& describe();
  const MonitorDescription& description() const override { return describe(); }

  /// The filtered force (N) and torque (N m) after the last sample, tare removed when relative.
  const Eigen::Vector3d& filtered_force_n() const { return force_n_; }
  const Eigen::Vector3d& filtered_torque_nm() const { return torque_nm_; }

 protected:
  std::vector<std::string> configure(const ParamValues& values) override;
  void start(Stamp start) override;
  Verdict sample(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm,
                 std::optional<double> dt_s) override;

 private:
  // One watched quantity (force or torque): its limit and since when it has been above it.
  struct Watch {
    double limit = 0.0;  // 0: not watched
    std::optional<Stamp> over_since;
  };
  std::optional<Verdict> check(Watch& watch, double value, Stamp stamp, const char* quantity, const char* unit) const;

  Watch force_watch_;
  Watch torque_watch_;
  Axis axis_ = Axis::kNorm;
  std::chrono::nanoseconds dwell_{0};
  bool relative_ = false;
  LowPass3 force_filter_;
  LowPass3 torque_filter_;
  Eigen::Vector3d force_tare_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_tare_nm_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nm_ = Eigen::Vector3d::Zero();
};

}  // namespace rigger::monitor
