#include "yank_monitor.hpp"

#include <cstdio>

namespace rigger::monitor {

const MonitorDescription& YankMonitor::describe() {
  static const MonitorDescription kDescription{
      "YankMonitor",
      "Fails with YANK_LIMIT when the filtered time derivative of the wrist force exceeds the threshold "
      "(a slip, a collision, a grasp that did not hold); fails with SENSOR_STALE or SENSOR_INVALID when the "
      "wrench stream stops or is corrupt. Never succeeds.",
      {ParamSpec{"max_yank_n_per_s", ParamType::kNumber, "N/s", 1.0, 10000000.0, std::nullopt, {},
                 "Yank threshold: the monitor fires when the filtered yank exceeds it."},
       axis_param("yank component"), cutoff_param(10.0, 200.0), max_sample_age_param()},
      true};
  return kDescription;
}

std::vector<std::string> YankMonitor::configure(const ParamValues& values) {
  max_yank_n_per_s_ = values.number("max_yank_n_per_s");
  axis_ = axis_from_string(values.string("axis"));
  estimator_ = YankEstimator(time_constant_s(values.number("cutoff_hz")));
  return {};
}

void YankMonitor::start(Stamp) { estimator_.reset(); }

Verdict YankMonitor::sample(Stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d&, std::optional<double> dt_s) {
  const double yank = magnitude(estimator_.update(force_n, dt_s.value_or(0.0)), axis_);
  if (!(yank > max_yank_n_per_s_)) return Verdict::ok();
  char text[128];
  std::snprintf(text, sizeof text, "yank %s %.0f N/s above the threshold %.0f N/s", std::string(to_string(axis_)).c_str(),
                yank, max_yank_n_per_s_);
  return Verdict::fire(kCodeYankLimit, text, yank);
}

}  // namespace rigger::monitor
