#include <gtest/gtest.h>

#include "monitor_test_util.hpp"
#include "timer_monitor.hpp"

namespace rigger::monitor {
namespace {

using nlohmann::json;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using std::chrono::seconds;
using testing::kT0;

TEST(TimerMonitor, FiresExactlyAtItsDuration) {
  TimerMonitor timer;
  ASSERT_TRUE(timer.reset(json{{"duration_s", 2.5}}, kT0).ok());
  EXPECT_EQ(timer.next_deadline(), kT0 + milliseconds(2500));
  EXPECT_FALSE(timer.on_time(kT0).fired());
  EXPECT_FALSE(timer.on_time(kT0 + milliseconds(2500) - nanoseconds(1)).fired());
  const Verdict verdict = timer.on_time(kT0 + milliseconds(2500));
  ASSERT_TRUE(verdict.fired());
  EXPECT_EQ(verdict.code, kCodeTimeout);
  EXPECT_DOUBLE_EQ(verdict.value, 2.5);
  EXPECT_EQ(verdict.message, "no result within 2.500 s (2.500 s elapsed)");
}

TEST(TimerMonitor, StaysFiredUntilReset) {
  TimerMonitor timer;
  ASSERT_TRUE(timer.reset(json{{"duration_s", 1}}, kT0).ok());
  const Verdict first = timer.on_time(kT0 + seconds(3));
  ASSERT_TRUE(first.fired());
  EXPECT_TRUE(timer.fired());
  EXPECT_FALSE(timer.next_deadline().has_value());
  const Verdict later = timer.on_time(kT0 + seconds(10));
  EXPECT_EQ(later.code, kCodeTimeout);
  EXPECT_DOUBLE_EQ(later.value, first.value) << "the latched verdict is repeated, not recomputed";
  EXPECT_TRUE(timer.on_wrench(kT0 + seconds(11), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).fired());

  ASSERT_TRUE(timer.reset(json{{"duration_s", 1}}, kT0 + seconds(20)).ok());
  EXPECT_FALSE(timer.fired());
  EXPECT_FALSE(timer.on_time(kT0 + seconds(20)).fired());
  EXPECT_TRUE(timer.on_time(kT0 + seconds(21)).fired());
}

TEST(TimerMonitor, IgnoresWrenchSamplesAndNeverGoesStale) {
  TimerMonitor timer;
  ASSERT_TRUE(timer.reset(json{{"duration_s", 100}}, kT0).ok());
  EXPECT_FALSE(timer.on_wrench(kT0 + seconds(1), Eigen::Vector3d::Constant(NAN), Eigen::Vector3d::Zero()).fired());
  EXPECT_FALSE(timer.on_time(kT0 + seconds(99)).fired()) << "no wrench for 99 s is not a fault of a timer";
}

TEST(TimerMonitor, NeverReportsSuccess) {
  TimerMonitor timer;
  ASSERT_TRUE(timer.reset(json{{"duration_s", 0.5}}, kT0).ok());
  for (int ms = 0; ms <= 1000; ms += 10) {
    const Verdict verdict = timer.on_time(kT0 + milliseconds(ms));
    EXPECT_EQ(verdict.fired(), ms >= 500) << ms;
  }
}

TEST(TimerMonitor, NotArmedBeforeReset) {
  TimerMonitor timer;
  EXPECT_FALSE(timer.armed());
  EXPECT_EQ(timer.on_time(kT0).code, kCodeNotArmed);
  EXPECT_FALSE(timer.next_deadline().has_value());
}

}  // namespace
}  // namespace rigger::monitor
