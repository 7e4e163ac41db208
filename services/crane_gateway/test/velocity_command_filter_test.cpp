#include "velocity_command_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rigger::crane_gateway {
namespace {

using namespace std::chrono_literals;

const WallTime kT0 = WallTime(std::chrono::seconds(1'700'000'000));

VelocityCommand command(double vx, WallTime stamp, std::uint64_t seq) {
  VelocityCommand c;
  c.velocity_mps = {vx, 0.0, 0.0};
  c.stamp = stamp;
  c.seq = seq;
  return c;
}

TEST(VelocityCommandFilter, NothingHeldMeansZero) {
  const VelocityCommandFilter filter(100ms);
  EXPECT_TRUE(filter.setpoint(kT0).isZero());
  EXPECT_FALSE(filter.fresh(kT0));
}

TEST(VelocityCommandFilter, FreshCommandUntilItsTimeout) {
  VelocityCommandFilter filter(100ms);
  EXPECT_EQ(filter.offer(command(0.2, kT0, 1), kT0 + 10ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(filter.setpoint(kT0 + 10ms).x(), 0.2);
  EXPECT_DOUBLE_EQ(filter.setpoint(kT0 + 100ms).x(), 0.2);  // exactly at the timeout
  EXPECT_TRUE(filter.setpoint(kT0 + 100ms + 1ns).isZero());
  EXPECT_FALSE(filter.fresh(kT0 + 100ms + 1ns));
}

TEST(VelocityCommandFilter, StaleCommandsAreNeverApplied) {
  VelocityCommandFilter filter(100ms);
  EXPECT_EQ(filter.offer(command(0.2, kT0, 1), kT0 + 100ms + 1ns), CommandVerdict::kStale);
  EXPECT_TRUE(filter.setpoint(kT0 + 100ms + 1ns).isZero());
  EXPECT_EQ(filter.offer(command(0.2, kT0, 2), kT0 + 100ms), CommandVerdict::kAccepted);
}

TEST(VelocityCommandFilter, FutureStampsBeyondTheSkewAreRejected) {
  VelocityCommandFilter filter(100ms, 20ms);
  EXPECT_EQ(filter.offer(command(0.1, kT0 + 21ms, 1), kT0), CommandVerdict::kFromTheFuture);
  EXPECT_EQ(filter.offer(command(0.1, kT0 + 20ms, 1), kT0), CommandVerdict::kAccepted);
}

TEST(VelocityCommandFilter, SequenceMustIncreaseWithinAStream) {
  VelocityCommandFilter filter(100ms);
  ASSERT_EQ(filter.offer(command(0.1, kT0, 10), kT0), CommandVerdict::kAccepted);
  EXPECT_EQ(filter.offer(command(0.3, kT0 + 5ms, 10), kT0 + 5ms), CommandVerdict::kNotNewer);
  EXPECT_EQ(filter.offer(command(0.3, kT0 + 5ms, 9), kT0 + 5ms), CommandVerdict::kNotNewer);
  EXPECT_DOUBLE_EQ(filter.setpoint(kT0 + 5ms).x(), 0.1);  // the newer command stays
  EXPECT_EQ(filter.offer(command(0.3, kT0 + 6ms, 11), kT0 + 6ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(filter.setpoint(kT0 + 6ms).x(), 0.3);
}

TEST(VelocityCommandFilter, ARestartedSenderStartsANewStreamAfterExpiry) {
  VelocityCommandFilter filter(100ms);
  ASSERT_EQ(filter.offer(command(0.1, kT0, 500), kT0), CommandVerdict::kAccepted);
  const WallTime later = kT0 + 150ms;  // the old stream has expired
  EXPECT_EQ(filter.offer(command(-0.1, later, 0), later), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(filter.setpoint(later).x(), -0.1);
}

TEST(VelocityCommandFilter, ABurstOfOldSamplesAfterANetworkDrop) {
  // The sender published every 10 ms; the network held 50 samples back and delivers them at
  // once, 500 ms after the first was sent.
  VelocityCommandFilter filter(100ms);
  const WallTime now = kT0 + 500ms;
  int accepted = 0;
  for (std::uint64_t seq = 0; seq < 50; ++seq) {
    const WallTime stamp = kT0 + std::chrono::milliseconds(10 * seq);
    const auto verdict = filter.offer(command(0.01 * static_cast<double>(seq), stamp, seq), now);
    if (verdict == CommandVerdict::kAccepted) {
      ++accepted;
      EXPECT_LE(now - stamp, 100ms);
    } else {
      EXPECT_EQ(verdict, CommandVerdict::kStale);
    }
  }
  EXPECT_EQ(accepted, 10);  // stamps 400..490 ms
  EXPECT_DOUBLE_EQ(filter.setpoint(now).x(), 0.49);
  EXPECT_TRUE(filter.setpoint(kT0 + 590ms + 1ns).isZero());
}

TEST(VelocityCommandFilter, ResetForgetsAndRejectsOlderStamps) {
  VelocityCommandFilter filter(1s);
  ASSERT_EQ(filter.offer(command(0.2, kT0, 1), kT0), CommandVerdict::kAccepted);
  const WallTime reconnect = kT0 + 100ms;
  filter.reset(reconnect);
  EXPECT_TRUE(filter.setpoint(reconnect).isZero());  // still young, but from before
  EXPECT_EQ(filter.offer(command(0.2, kT0 + 50ms, 2), reconnect + 1ms),
            CommandVerdict::kBeforeReconnect);
  EXPECT_EQ(filter.offer(command(0.2, reconnect, 3), reconnect + 1ms),
            CommandVerdict::kBeforeReconnect);
  EXPECT_EQ(filter.offer(command(0.3, reconnect + 1ns, 1), reconnect + 1ms),
            CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(filter.setpoint(reconnect + 2ms).x(), 0.3);
}

TEST(VelocityCommandFilter, RejectsNonFiniteVelocities) {
  VelocityCommandFilter filter(100ms);
  VelocityCommand c = command(0.0, kT0, 1);
  c.velocity_mps.y() = std::nan("");
  EXPECT_EQ(filter.offer(c, kT0), CommandVerdict::kNotFinite);
  c.velocity_mps.y() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(filter.offer(c, kT0), CommandVerdict::kNotFinite);
  EXPECT_TRUE(filter.setpoint(kT0).isZero());
}

TEST(VelocityCommandFilter, RejectsBadParameters) {
  EXPECT_THROW(VelocityCommandFilter(0ms), std::invalid_argument);
  EXPECT_THROW(VelocityCommandFilter(10ms, -1ms), std::invalid_argument);
  EXPECT_EQ(verdict_name(CommandVerdict::kBeforeReconnect), "before_reconnect");
}

}  // namespace
}  // namespace rigger::crane_gateway
