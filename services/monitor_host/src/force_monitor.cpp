#include "force_monitor.hpp"

#include <cstdio>

namespace rigger::monitor {

const MonitorDescription& ForceMonitor::describe() {
  static const MonitorDescription kDescription{
      "ForceMonitor",
      "Fails with FORCE_LIMIT when the filtered wrist force or torque stays above its limit for the dwell "
      "time; fails with SENSOR_STALE or SENSOR_INVALID when the wrench stream stops or is corrupt. Never "
      "succeeds.",
      {ParamSpec{"max_force_n", ParamType::kNumber, "N", 0.0, 100000.0, nlohmann::json(0.0), {},
                 "Force limit; 0 leaves the force unwatched (at least one of max_force_n and max_torque_nm must be > 0)."},
       ParamSpec{"max_torque_nm", ParamType::kNumber, "Nm", 0.0, 10000.0, nlohmann::json(0.0), {},
                 "Torque limit; 0 leaves the torque unwatched."},
       axis_param("force and torque component"),
       ParamSpec{"dwell_s", ParamType::kNumber, "s", 0.0, 10.0, nlohmann::json(0.02), {},
                 "How long the filtered value must stay above the limit before the monitor fires."},
       cutoff_param(20.0, 500.0),
       ParamSpec{"relative", ParamType::kBoolean, "", std::nullopt, std::nullopt, nlohmann::json(false), {},
                 "Apply the limits to the change from the first sample after the start (tare) instead of the "
                 "absolute wrench."},
       max_sample_age_param()},
      true};
  return kDescription;
}

std::vector<std::string> ForceMonitor::configure(const ParamValues& values) {
  force_watch_ = Watch{values.number("max_force_n"), std::nullopt};
  torque_watch_ = Watch{values.number("max_torque_nm"), std::nullopt};
  if (force_watch_.limit <= 0.0 && torque_watch_.limit <= 0.0) {
    return {"/max_force_n: expected a force limit > 0 N or a torque limit /max_torque_nm > 0 Nm, got neither"};
  }
  axis_ = axis_from_string(values.string("axis"));
  dwell_ = from_seconds(values.number("dwell_s"));
  relative_ = values.boolean("relative");
  const double tau_s = time_constant_s(values.number("cutoff_hz"));
  force_filter_ = LowPass3(tau_s);
  torque_filter_ = LowPass3(tau_s);
  return {};
}

void ForceMonitor::start(Stamp) {
  force_filter_.reset();
  torque_filter_.reset();
  force_watch_.over_since.reset();
  torque_watch_.over_since.reset();
  force_tare_n_.setZero();
  torque_tare_nm_.setZero();
  force_n_.setZero();
  torque_nm_.setZero();
}

Verdict ForceMonitor::sample(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm,
                             std::optional<double> dt_s) {
  if (!dt_s && relative_) {
    force_tare_n_ = force_n;
    torque_tare_nm_ = torque_nm;
  }
  force_n_ = force_filter_.update(force_n, dt_s.value_or(0.0)) - force_tare_n_;
  torque_nm_ = torque_filter_.update(torque_nm, dt_s.value_or(0.0)) - torque_tare_nm_;
  if (auto fired = check(force_watch_, magnitude(force_n_, axis_), stamp, "force", "N")) return *fired;
  if (auto fired = check(torque_watch_, magnitude(torque_nm_, axis_), stamp, "torque", "Nm")) return *fired;
  return Verdict::ok();
}

std::optional<Verdict> ForceMonitor::check(Watch& watch, double value, Stamp stamp, const char* quantity,
                                           const char* unit) const {
  if (watch.limit <= 0.0) return std::nullopt;
  if (!(value > watch.limit)) {
    watch.over_since.reset();
    return std::nullopt;
  }
  if (!watch.over_since) watch.over_since = stamp;
  const auto over_for = std::chrono::duration_cast<std::chrono::nanoseconds>(stamp - *watch.over_since);
  if (over_for < dwell_) return std::nullopt;
  char text[160];
  std::snprintf(text, sizeof text, "%s%s %s %.1f %s above the limit %.1f %s for %.3f s", relative_ ? "change of " : "",
                quantity, std::string(to_string(axis_)).c_str(), value, unit, watch.limit, unit, to_seconds(over_for));
  return Verdict::fire(kCodeForceLimit, text, value);
}

}  // namespace rigger::monitor
