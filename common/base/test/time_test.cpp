#include "rigger/base/time.hpp"

#include <gtest/gtest.h>

namespace rigger {
namespace {

TEST(Time, UnixNanosecondsRoundTrip) {
  const std::int64_t ns = 1'700'000'000'123'456'789;
  EXPECT_EQ(to_unix_ns(from_unix_ns(ns)), ns);
  EXPECT_EQ(to_unix_ns(from_unix_ns(0)), 0);
}

TEST(Time, SecondsConversions) {
  EXPECT_DOUBLE_EQ(to_seconds(std::chrono::milliseconds(250)), 0.25);
  EXPECT_EQ(from_seconds(0.5), std::chrono::milliseconds(500));
}

}  // namespace
}  // namespace rigger
