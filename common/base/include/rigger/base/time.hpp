#pragma once
/// @file
/// Time conventions: stamps on the wire are wall-clock (system_clock) time since the Unix epoch, as in
/// ROS 2; deadlines and timeouts inside a process use steady_clock.

#include <chrono>
#include <cstdint>

namespace rigger {

using WallTime = std::chrono::system_clock::time_point;
using SteadyTime = std::chrono::steady_clock::time_point;
using Seconds = std::chrono::duration<double>;

/// Nanoseconds since the Unix epoch.
inline std::int64_t to_unix_ns(WallTime t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}
inline WallTime from_unix_ns(std::int64_t ns) {
  return WallTime(std::chrono::duration_cast<WallTime::duration>(std::chrono::nanoseconds(ns)));
}
/// A duration in (fractional) seconds, as used in configuration files and recipes (`timeout_s`).
template <typename Rep, typename Period>
double to_seconds(std::chrono::duration<Rep, Period> d) {
  return std::chrono::duration_cast<Seconds>(d).count();
}
/// The steady-clock duration for a (fractional) number of seconds.
inline std::chrono::nanoseconds from_seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Seconds(s));
}

}  // namespace rigger
