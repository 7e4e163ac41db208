#include "command_gate.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace rigger::cell_sim {
namespace {

using namespace std::chrono_literals;

class CommandGateTest : public ::testing::Test {
 protected:
  CommandGate gate_{50ms, 500ms};
  const WallTime now_ = WallTime(std::chrono::seconds(1'800'000'000));
};

TEST_F(CommandGateTest, AcceptsAFreshCommandAndHoldsItForItsTimeout) {
  EXPECT_EQ(gate_.offer(now_ - 10ms, 1, 0.1, now_), GateVerdict::kAccepted);
  ASSERT_TRUE(gate_.expiry().has_value());
  EXPECT_EQ(*gate_.expiry(), now_ - 10ms + 100ms);
}

TEST_F(CommandGateTest, RefusesACommandOlderThanItsOwnTimeout) {
  EXPECT_EQ(gate_.offer(now_ - 101ms, 1, 0.1, now_), GateVerdict::kStale);
  EXPECT_FALSE(gate_.expiry().has_value());
  // The same age passes with a longer timeout: the command's own timeout decides.
  EXPECT_EQ(gate_.offer(now_ - 101ms, 1, 0.2, now_), GateVerdict::kAccepted);
}

TEST_F(CommandGateTest, RefusesCommandsFromTheFutureBeyondTheSkew) {
  EXPECT_EQ(gate_.offer(now_ + 51ms, 1, 0.1, now_), GateVerdict::kFromTheFuture);
  EXPECT_EQ(gate_.offer(now_ + 49ms, 1, 0.1, now_), GateVerdict::kAccepted);
}

TEST_F(CommandGateTest, RefusesASequenceNumberNotAboveTheCurrentOneWhileItHolds) {
  ASSERT_EQ(gate_.offer(now_, 10, 0.1, now_), GateVerdict::kAccepted);
  EXPECT_EQ(gate_.offer(now_ + 5ms, 10, 0.1, now_ + 5ms), GateVerdict::kNotNewer);
  EXPECT_EQ(gate_.offer(now_ + 5ms, 9, 0.1, now_ + 5ms), GateVerdict::kNotNewer);
  EXPECT_EQ(gate_.offer(now_ + 5ms, 11, 0.1, now_ + 5ms), GateVerdict::kAccepted);
}

TEST_F(CommandGateTest, AnExpiredStreamMayRestartFromALowerSequenceNumber) {
  ASSERT_EQ(gate_.offer(now_, 10, 0.1, now_), GateVerdict::kAccepted);
  const WallTime later = now_ + 150ms;  // the command expired at now + 100 ms
  EXPECT_EQ(gate_.offer(later, 0, 0.1, later), GateVerdict::kAccepted);
}

TEST_F(CommandGateTest, RefusesNonPositiveOrNonFiniteTimeouts) {
  EXPECT_EQ(gate_.offer(now_, 1, 0.0, now_), GateVerdict::kBadTimeout);
  EXPECT_EQ(gate_.offer(now_, 1, -1.0, now_), GateVerdict::kBadTimeout);
  EXPECT_EQ(gate_.offer(now_, 1, std::numeric_limits<double>::quiet_NaN(), now_), GateVerdict::kBadTimeout);
  EXPECT_EQ(gate_.offer(now_, 1, std::numeric_limits<double>::infinity(), now_), GateVerdict::kBadTimeout);
}

TEST_F(CommandGateTest, CapsTheHoldTimeAtTheMaximumTimeout) {
  ASSERT_EQ(gate_.offer(now_, 1, 60.0, now_), GateVerdict::kAccepted);
  EXPECT_EQ(*gate_.expiry(), now_ + 500ms);
}

TEST_F(CommandGateTest, ResetForgetsTheStream) {
  ASSERT_EQ(gate_.offer(now_, 10, 0.1, now_), GateVerdict::kAccepted);
  gate_.reset();
  EXPECT_FALSE(gate_.expiry().has_value());
  EXPECT_EQ(gate_.offer(now_, 3, 0.1, now_), GateVerdict::kAccepted);
}

TEST(CommandGate, RejectsUnusableParameters) {
  EXPECT_THROW(CommandGate(-1ms, 100ms), std::invalid_argument);
  EXPECT_THROW(CommandGate(0ms, 0ms), std::invalid_argument);
}

TEST(CommandGate, NamesEveryVerdict) {
  EXPECT_EQ(verdict_name(GateVerdict::kStale), "stale");
  EXPECT_EQ(verdict_name(GateVerdict::kNotNewer), "not_newer");
  EXPECT_EQ(verdict_name(GateVerdict::kFromTheFuture), "from_the_future");
}

}  // namespace
}  // namespace rigger::cell_sim
