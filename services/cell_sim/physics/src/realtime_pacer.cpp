#include "rigger/sim/realtime_pacer.hpp"

#include <cmath>

namespace rigger::sim {
namespace {
double sane_rate(double rate) { return std::isfinite(rate) && rate > 0.0 ? rate : 1.0; }
}  // namespace

RealTimePacer::RealTimePacer(double rate) : rate_(sane_rate(rate)) {}

void RealTimePacer::start(WallClock::time_point wall_now, std::chrono::nanoseconds sim_now) {
  wall_anchor_ = wall_now;
  sim_anchor_ = sim_now;
}

void RealTimePacer::set_rate(double rate, WallClock::time_point wall_now,
                             std::chrono::nanoseconds sim_now) {
  rate_ = sane_rate(rate);
  start(wall_now, sim_now);
}

std::chrono::nanoseconds RealTimePacer::target_sim_time(WallClock::time_point wall_now) const {
  const auto wall_elapsed = std::chrono::duration<double>(wall_now - wall_anchor_);
  // Round, not truncate: a double of 0.3 s must not become 299999999 ns.
  return sim_anchor_ + std::chrono::round<std::chrono::nanoseconds>(
                           std::chrono::duration<double>(wall_elapsed.count() * rate_));
}

RealTimePacer::WallClock::time_point RealTimePacer::wall_time_for(
    std::chrono::nanoseconds sim_time) const {
  const auto sim_elapsed = std::chrono::duration<double>(sim_time - sim_anchor_);
  return wall_anchor_ + std::chrono::round<WallClock::duration>(
                            std::chrono::duration<double>(sim_elapsed.count() / rate_));
}

std::chrono::nanoseconds RealTimePacer::lag(WallClock::time_point wall_now,
                                            std::chrono::nanoseconds sim_now) const {
  return target_sim_time(wall_now) - sim_now;
}

}  // namespace rigger::sim
