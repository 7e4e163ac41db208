#include "boundary.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace rigger::ros2_bridge {
namespace {

using namespace std::chrono_literals;

const WallTime kNow = from_unix_ns(1'700'000'000'000'000'000);

TEST(AgeCheck, FreshUpToTheMaximumAgeAndSkew) {
  const AgeLimits limits{100ms, 20ms};
  EXPECT_EQ(check_age(kNow, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow - 100ms, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow - 101ms, kNow, limits), AgeVerdict::kStale);
  EXPECT_EQ(check_age(kNow + 20ms, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow + 21ms, kNow, limits), AgeVerdict::kFromTheFuture);
}

TEST(AgeCheck, AZeroStampIsUnstampedNotAncient) {
  EXPECT_EQ(check_age(WallTime{}, kNow, AgeLimits{}), AgeVerdict::kUnstamped);
  EXPECT_EQ(age_verdict_name(AgeVerdict::kUnstamped), "unstamped");
  EXPECT_EQ(age_verdict_name(AgeVerdict::kStale), "stale");
}

Vector6d twist(double vx, double vy, double vz, double wx, double wy, double wz) {
  Vector6d t;
  t << vx, vy, vz, wx, wy, wz;
  return t;
}

TEST(TwistLimit, WithinLimitsPassesUnchanged) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kClamp};
  const auto r = limit_twist(twist(0.1, -0.2, 0.0, 0.0, 0.3, -0.4), limits);  // norms 0.224, 0.5
  EXPECT_EQ(r.verdict, TwistVerdict::kWithin);
  EXPECT_TRUE(r.send());
  EXPECT_EQ(r.twist, twist(0.1, -0.2, 0.0, 0.0, 0.3, -0.4));
}

TEST(TwistLimit, ClampScalesEachPartToItsLimitKeepingDirection) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kClamp};
  const auto r = limit_twist(twist(0.3, 0.4, 0.0, 0.0, 0.0, 0.1), limits);  // linear 0.5 > 0.25
  ASSERT_EQ(r.verdict, TwistVerdict::kClamped);
  EXPECT_TRUE(r.send());
  EXPECT_NEAR(r.twist.head<3>().norm(), 0.25, 1e-12);
  EXPECT_NEAR(r.twist(0), 0.15, 1e-12);
  EXPECT_NEAR(r.twist(1), 0.2, 1e-12);
  EXPECT_EQ(r.twist(5), 0.1);  // the angular part was within its limit: untouched

  const auto a = limit_twist(twist(0, 0, 0.1, 0, -2.0, 0), limits);
  ASSERT_EQ(a.verdict, TwistVerdict::kClamped);
  EXPECT_EQ(a.twist(2), 0.1);
  EXPECT_NEAR(a.twist(4), -0.5, 1e-12);
}

TEST(TwistLimit, RefuseDropsAnythingAboveALimit) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kRefuse};
  const auto r = limit_twist(twist(0, 0, 0, 0, 0, 0.51), limits);
  EXPECT_EQ(r.verdict, TwistVerdict::kOverLimit);
  EXPECT_FALSE(r.send());
  EXPECT_EQ(r.twist, Vector6d::Zero());
  EXPECT_EQ(limit_twist(twist(0.25, 0, 0, 0, 0, 0.5), limits).verdict, TwistVerdict::kWithin);
}

TEST(TwistLimit, NotFiniteIsAlwaysRefused) {
  const TwistLimits clamp{0.25, 0.5, OverLimit::kClamp};
  EXPECT_EQ(limit_twist(twist(std::nan(""), 0, 0, 0, 0, 0), clamp).verdict, TwistVerdict::kNotFinite);
  const auto r = limit_twist(twist(0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0), clamp);
  EXPECT_EQ(r.verdict, TwistVerdict::kNotFinite);
  EXPECT_FALSE(r.send());
}

TEST(RefusalCounter, LogsTheFirstThenAtMostOncePerInterval) {
  RefusalCounter c(1s);
  const SteadyTime t0{};
  EXPECT_TRUE(c.count(t0));
  EXPECT_EQ(c.batch(), 1u);
  EXPECT_FALSE(c.count(t0 + 100ms));
  EXPECT_FALSE(c.count(t0 + 999ms));
  EXPECT_TRUE(c.count(t0 + 1000ms));
  EXPECT_EQ(c.batch(), 3u);  // the two silent ones and this one
  EXPECT_EQ(c.total(), 4u);
  EXPECT_FALSE(c.count(t0 + 1500ms));
  EXPECT_TRUE(c.count(t0 + 2500ms));
  EXPECT_EQ(c.batch(), 2u);
  EXPECT_EQ(c.total(), 6u);
}

}  // namespace
}  // namespace rigger::ros2_bridge
