#pragma once
// Helpers for feeding synthetic wrench profiles to monitors.

#include <chrono>
#include <cmath>
#include <functional>
#include <optional>

#include <gtest/gtest.h>

#include "monitor.hpp"

namespace rigger::monitor::testing {

// An arbitrary wall-clock origin for the synthetic streams.
inline const Stamp kT0{std::chrono::seconds(1700000000)};

inline Stamp at(double t_s) { return kT0 + std::chrono::duration_cast<Stamp::duration>(from_seconds(t_s)); }
inline double since_t0(Stamp stamp) { return to_seconds(std::chrono::duration_cast<std::chrono::nanoseconds>(stamp - kT0)); }

struct Detection {
  std::optional<double> time_s;  // time (since kT0) of the first fired verdict
  Verdict verdict;
  double max_spacing_s = 0.0;    // the largest sample spacing fed
};

// Feeds force_at(t) (torque zero unless given) at the times time_at(k), k = 0, 1, ..., while
// time_at(k) <= end_s, stopping at the first fired verdict.
inline Detection run_profile(Monitor& monitor, const std::function<Eigen::Vector3d(double)>& force_at,
                             const std::function<double(int)>& time_at, double end_s,
                             const std::function<Eigen::Vector3d(double)>& torque_at = nullptr) {
  Detection detection;
  std::optional<double> previous;
  for (int k = 0;; ++k) {
    const double t = time_at(k);
    if (t > end_s) break;
    if (previous) detection.max_spacing_s = std::max(detection.max_spacing_s, t - *previous);
    previous = t;
    const Eigen::Vector3d torque = torque_at ? torque_at(t) : Eigen::Vector3d::Zero();
    const Verdict verdict = monitor.on_wrench(at(t), force_at(t), torque);
    EXPECT_TRUE(verdict.kind == Verdict::Kind::kOk || verdict.kind == Verdict::Kind::kFired);
    if (verdict.fired()) {
      detection.time_s = t;
      detection.verdict = verdict;
      return detection;
    }
  }
  return detection;
}

// A monitor of type M armed at kT0 with `params` (which must be valid).
template <typename M>
M armed(const nlohmann::json& params) {
  M monitor;
  const ParamCheck check = monitor.reset(params, kT0);
  EXPECT_TRUE(check.ok()) << check.message();
  return monitor;
}

// Regular sampling with period T.
inline std::function<double(int)> every(double period_s) {
  return [period_s](int k) { return k * period_s; };
}

// Solves f(t) = 0 for t in [lo, hi] with f(lo) < 0 < f(hi), to 1 ns.
inline double solve_increasing(const std::function<double(double)>& f, double lo, double hi) {
  while (hi - lo > 1e-9) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rigger::monitor::testing
