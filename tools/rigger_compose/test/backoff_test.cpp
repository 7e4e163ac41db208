#include "rigger/compose/backoff.hpp"

#include <gtest/gtest.h>

namespace rigger::compose {
namespace {

using std::chrono::milliseconds;

TEST(RestartBackoffTest, DoublesFromHalfASecondUpToTenSeconds) {
  RestartBackoff b;
  const milliseconds expected[] = {milliseconds(500),  milliseconds(1000),  milliseconds(2000), milliseconds(4000),
                                   milliseconds(8000), milliseconds(10000), milliseconds(10000)};
  for (const auto e : expected) EXPECT_EQ(b.next_delay(milliseconds(100)), e);
}

TEST(RestartBackoffTest, AnInstanceThatRanThirtySecondsResetsIt) {
  RestartBackoff b;
  b.next_delay(milliseconds(0));
  b.next_delay(milliseconds(0));
  EXPECT_EQ(b.next_delay(milliseconds(29999)), milliseconds(2000));  // just short of stable: keeps doubling
  EXPECT_EQ(b.next_delay(milliseconds(30000)), milliseconds(500));
  EXPECT_EQ(b.next_delay(milliseconds(10)), milliseconds(1000));
}

TEST(RestartBackoffTest, ResetForgetsEarlierCrashes) {
  RestartBackoff b;
  b.next_delay(milliseconds(0));
  b.next_delay(milliseconds(0));
  b.reset();
  EXPECT_EQ(b.next_delay(milliseconds(0)), milliseconds(500));
}

}  // namespace
}  // namespace rigger::compose
