#pragma once
// The physics' own force and tool speed, for comparing with what the console's plots page draws: the
// wrench the simulated F/T sensor publishes (rigger/robot/wrench, the series the console plots as |F|)
// and the robot's tool speed (rigger/robot/state), each with its publisher's wall-clock stamp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing::scenario {

class PhysicsTrace {
 public:
  explicit PhysicsTrace(Cell& cell)
      : wrench_(cell.participant(), protocol::robot::kWrench, deep(protocol::robot::kWrench)),
        robot_(cell.participant(), protocol::robot::kState, deep(protocol::robot::kState)) {
    cell.loop().on_data(wrench_, [this] {
      wrench_.take([this](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
        force_.emplace_back(stamp_s(w.header.stamp), dds::to_domain(w.wrench.force));
      });
    });
    cell.loop().on_data(robot_, [this] {
      robot_.take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        speed_.emplace_back(stamp_s(s.header.stamp), dds::to_domain(s.tool_twist.linear).norm());
      });
    });
  }

  /// |mean force| over the samples stamped in (from, t], as the console averages the wrench since its
  /// previous plot row; NaN when there is none.
  double force_at(double from, double t) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (auto it = first_after(force_, from); it != force_.end() && it->first <= t; ++it, ++n) sum += it->second;
    return n > 0 ? (sum / n).norm() : std::nan("");
  }
  /// The tool speed of the latest sample stamped at or before `t` (the console plots the latest); NaN
  /// before the first.
  double speed_at(double t) const {
    const auto it = first_after(speed_, t);
    return it == speed_.begin() ? std::nan("") : std::prev(it)->second;
  }

  std::size_t force_samples() const { return force_.size(); }
  std::size_t speed_samples() const { return speed_.size(); }

 private:
  template <typename T>
  static dds::Qos deep(const protocol::Topic<T>& topic) {
    dds::Qos q = dds::qos::of(topic.qos);
    q.keep_last(1024);  // the test's loop may be busy for a while; the 500 Hz wrench must not be overwritten
    return q;
  }
  static double stamp_s(const rigger_geometry_Time& t) { return t.sec + 1e-9 * t.nanosec; }
  template <typename V>
  static typename std::vector<std::pair<double, V>>::const_iterator first_after(const std::vector<std::pair<double, V>>& v,
                                                                                double t) {
    return std::upper_bound(v.begin(), v.end(), t, [](double x, const auto& s) { return x < s.first; });
  }

  dds::Reader<rigger_sensing_WrenchStamped> wrench_;
  dds::Reader<rigger_robot_RobotState> robot_;
  std::vector<std::pair<double, Eigen::Vector3d>> force_;  // in arrival order; stamps of one publisher ascend
  std::vector<std::pair<double, double>> speed_;
};

/// Rows in a window of the series' peaks over windows: a sample that arrives a row late moves between
/// neighbouring rows, and stays in most windows that hold either.
constexpr int kPeakWindowRows = 3;

/// A plotted series against the physics over [from, to]: the rows in it, the peaks (of one row and of the
/// mean over kPeakWindowRows rows in a row), the largest and the median difference row by row.
struct SeriesComparison {
  int rows = 0;
  double first_t = 0.0, last_t = 0.0;
  double page_peak = 0.0, physics_peak = 0.0;
  double page_window_peak = 0.0, physics_window_peak = 0.0;
  double median_error = 0.0, max_error = 0.0;

  std::string describe(const char* what, const char* unit) const {
    char s[400];
    std::snprintf(s, sizeof s,
                  "%s: %d rows over %.2f s; peak page %.4f %s, physics %.4f %s (over %d rows: %.4f, %.4f); row error "
                  "median %.4f, max %.4f %s",
                  what, rows, last_t - first_t, page_peak, unit, physics_peak, unit, kPeakWindowRows, page_window_peak,
                  physics_window_peak, median_error, max_error, unit);
    return s;
  }
};

/// Compares `series` ([[t, value], ...] as e2e.mjs read them off the chart) with `physics(previous_t, t)`
/// over the rows with t in [from, to] (previous_t: the row before's time, or t - first_row_s for the
/// first row); rows without a physics value are skipped.
template <typename Physics>
SeriesComparison compare_series(const nlohmann::json& series, double from, double to, double first_row_s,
                                Physics physics) {
  SeriesComparison c;
  std::vector<double> errors, pages, truths;
  double previous_t = std::nan("");
  for (const auto& row : series) {
    const double t = row.at(0).get<double>(), page = row.at(1).get<double>();
    const double row_from = std::isnan(previous_t) ? t - first_row_s : previous_t;
    previous_t = t;
    if (t < from || t > to) continue;
    const double truth = physics(row_from, t);
    if (std::isnan(truth)) continue;
    if (c.rows++ == 0) c.first_t = t;
    c.last_t = t;
    c.page_peak = std::max(c.page_peak, page);
    c.physics_peak = std::max(c.physics_peak, truth);
    errors.push_back(std::abs(page - truth));
    pages.push_back(page);
    truths.push_back(truth);
  }
  const auto window_peak = [](const std::vector<double>& v) {
    double peak = 0.0;
    for (std::size_t i = 0; i + kPeakWindowRows <= v.size(); ++i)
      peak = std::max(peak, std::accumulate(v.begin() + static_cast<std::ptrdiff_t>(i),
                                            v.begin() + static_cast<std::ptrdiff_t>(i + kPeakWindowRows), 0.0) /
                                kPeakWindowRows);
    return peak;
  };
  c.page_window_peak = window_peak(pages);
  c.physics_window_peak = window_peak(truths);
  if (!errors.empty()) {
    std::sort(errors.begin(), errors.end());
    c.median_error = errors[errors.size() / 2];
    c.max_error = errors.back();
  }
  return c;
}

}  // namespace rigger::testing::scenario
