#pragma once
// Pacing the simulation against the wall clock: how far simulated time should have advanced by a
// given wall time at a requested rate (1 = real time, 3 = three times faster).  Pure; the clock is
// passed in, so it is testable without sleeping.

#include <chrono>

namespace rigger::sim {

class RealTimePacer {
 public:
  using WallClock = std::chrono::steady_clock;

  /// rate > 0: simulated seconds per wall second.  Values <= 0 or not finite are taken as 1.
  explicit RealTimePacer(double rate = 1.0);

  /// Anchor: at `wall_now` the simulation is at `sim_now`.
  void start(WallClock::time_point wall_now, std::chrono::nanoseconds sim_now);

  /// Change the rate without a jump: re-anchors at (wall_now, sim_now).
  void set_rate(double rate, WallClock::time_point wall_now, std::chrono::nanoseconds sim_now);

  /// Simulated time the simulation should have reached at `wall_now`.
  [[nodiscard]] std::chrono::nanoseconds target_sim_time(WallClock::time_point wall_now) const;

  /// Wall time at which the simulation reaches `sim_time` (to sleep until).
  [[nodiscard]] WallClock::time_point wall_time_for(std::chrono::nanoseconds sim_time) const;

  /// How far the simulation at `sim_now` lags behind its target at `wall_now` (<= 0: on time).
  [[nodiscard]] std::chrono::nanoseconds lag(WallClock::time_point wall_now,
                                             std::chrono::nanoseconds sim_now) const;

  [[nodiscard]] double rate() const { return rate_; }

 private:
  double rate_ = 1.0;
  WallClock::time_point wall_anchor_{};
  std::chrono::nanoseconds sim_anchor_{0};
};

}  // namespace rigger::sim
