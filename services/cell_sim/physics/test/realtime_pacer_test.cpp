#include "rigger/sim/realtime_pacer.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;
using WallClock = RealTimePacer::WallClock;

TEST(RealTimePacer, TargetAdvancesAtTheRate) {
  RealTimePacer pacer(3.0);
  const WallClock::time_point start{};
  pacer.start(start, 10s);
  EXPECT_EQ(pacer.target_sim_time(start), 10s);
  EXPECT_EQ(pacer.target_sim_time(start + 100ms), 10s + 300ms);
  EXPECT_EQ(pacer.wall_time_for(10s + 300ms), start + 100ms);
  EXPECT_EQ(pacer.lag(start + 100ms, 10s + 250ms), 50ms);
  EXPECT_LE(pacer.lag(start + 100ms, 10s + 400ms).count(), 0);
}

TEST(RealTimePacer, RateChangeDoesNotJump) {
  RealTimePacer pacer(1.0);
  const WallClock::time_point start{};
  pacer.start(start, 0s);
  pacer.set_rate(2.0, start + 1s, 1s);
  EXPECT_EQ(pacer.target_sim_time(start + 1s), 1s);
  EXPECT_EQ(pacer.target_sim_time(start + 2s), 3s);
}

TEST(RealTimePacer, BadRatesMeanRealTime) {
  EXPECT_DOUBLE_EQ(RealTimePacer(0.0).rate(), 1.0);
  EXPECT_DOUBLE_EQ(RealTimePacer(-2.0).rate(), 1.0);
  EXPECT_DOUBLE_EQ(RealTimePacer(std::nan("")).rate(), 1.0);
}

}  // namespace
}  // namespace rigger::sim
