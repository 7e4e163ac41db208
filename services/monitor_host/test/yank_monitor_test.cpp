#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "monitor_test_util.hpp"
#include "yank_monitor.hpp"

namespace rigger::monitor {
namespace {

using nlohmann::json;
using std::chrono::milliseconds;
using testing::at;
using testing::every;
using testing::kT0;
using testing::run_profile;

constexpr double kPeriod = 0.001;  // 1 kHz wrench stream
constexpr double kE = 2.718281828459045;

YankMonitor armed(const json& params) { return testing::armed<YankMonitor>(params); }

// Time after the start of a force ramp of slope r at which the yank of H(s) = s/(τs+1)² exceeds y.
double ramp_crossing(double r, double y, double tau) {
  return testing::solve_increasing([&](double t) { return r * (1.0 - std::exp(-t / tau) * (1.0 + t / tau)) - y; }, 0.0,
                                   50.0 * tau);
}

TEST(YankMonitor, RampDetectionDelayMatchesTheDifferentiator) {
  const double tau = time_constant_s(10.0);
  const double threshold = 400.0;
  for (const double slope : {600.0, 1000.0, 5000.0}) {
    YankMonitor monitor = armed(json{{"max_yank_n_per_s", threshold}});
    const double t_s = 0.2;
    const auto detection = run_profile(
        monitor, [&](double t) { return Eigen::Vector3d(0, 0, -100.0 - (t > t_s ? slope * (t - t_s) : 0.0)); },
        every(kPeriod), 1.0);
    ASSERT_TRUE(detection.time_s.has_value()) << slope;
    const double expected = t_s + ramp_crossing(slope, threshold, tau);
    EXPECT_NEAR(*detection.time_s, expected, kPeriod) << "slope " << slope << " expected " << expected;
    EXPECT_EQ(detection.verdict.code, kCodeYankLimit);
    EXPECT_GT(detection.verdict.value, threshold);
  }
}

TEST(YankMonitor, ASlowRampBelowTheThresholdNeverFires) {
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  const auto detection =
      run_profile(monitor, [](double t) { return Eigen::Vector3d(350.0 * t, 0, 0); }, every(kPeriod), 2.0);
  EXPECT_FALSE(detection.time_s.has_value()) << "yank of a 350 N/s ramp converges to 350 N/s";
  EXPECT_NEAR(monitor.yank_n_per_s().x(), 350.0, 1.0);
}

TEST(YankMonitor, RampWithIrregularSampleSpacing) {
  const double tau = time_constant_s(10.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> spacing(0.3 * kPeriod, 1.7 * kPeriod);
  std::vector<double> times{0.0};
  while (times.back() < 1.0) times.push_back(times.back() + spacing(rng));
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  const auto detection = run_profile(
      monitor, [](double t) { return Eigen::Vector3d(t > 0.1 ? 2000.0 * (t - 0.1) : 0.0, 0, 0); },
      [&](int k) { return times[static_cast<std::size_t>(k)]; }, 0.99);
  ASSERT_TRUE(detection.time_s.has_value());
  const double expected = 0.1 + ramp_crossing(2000.0, 400.0, tau);
  // The kink at 0.1 s falls between samples; allow the largest spacing on either side.
  EXPECT_NEAR(*detection.time_s, expected, detection.max_spacing_s);
}

TEST(YankMonitor, StepFiresOnlyWhenItsPulseReachesTheThreshold) {
  // A force step S gives a yank pulse (S/τ)(t/τ)e^(−t/τ) peaking at S/(eτ).
  const double tau = time_constant_s(10.0);
  const double threshold = 400.0;
  const double just_below = 0.95 * threshold * kE * tau;
  const double well_above = 3.0 * threshold * kE * tau;
  const auto step_of = [](double size) {
    return [size](double t) { return Eigen::Vector3d(0, t >= 0.2 - 1e-9 ? size : 0.0, 0); };
  };
  YankMonitor small = armed(json{{"max_yank_n_per_s", threshold}});
  EXPECT_FALSE(run_profile(small, step_of(just_below), every(kPeriod), 1.0).time_s.has_value());
  YankMonitor large = armed(json{{"max_yank_n_per_s", threshold}});
  const auto detection = run_profile(large, step_of(well_above), every(kPeriod), 1.0);
  ASSERT_TRUE(detection.time_s.has_value());
  // Earlier root of (S/τ) u e^(−u) = Y, for the step taken half a sample before t = 0.2 s.
  const double u = testing::solve_increasing(
      [&](double x) { return well_above / tau * x * std::exp(-x) - threshold; }, 0.0, 1.0);
  EXPECT_NEAR(*detection.time_s, 0.2 - kPeriod / 2 + u * tau, kPeriod);
}

TEST(YankMonitor, SlipSpikeIsDetected) {
  // The load slips: the held force drops by 100 N within 20 ms (−5000 N/s) from a static 392 N.
  const double tau = time_constant_s(10.0);
  const double t_slip = 0.5;
  const auto slip = [&](double t) {
    const double drop = std::clamp((t - t_slip) / 0.02, 0.0, 1.0) * 100.0;
    return Eigen::Vector3d(0, 0, -392.0 + drop);
  };
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  const auto detection = run_profile(monitor, slip, every(kPeriod), 1.0);
  ASSERT_TRUE(detection.time_s.has_value());
  const double expected = t_slip + ramp_crossing(5000.0, 400.0, tau);
  EXPECT_LT(expected, t_slip + 0.02) << "the analytic crossing must fall within the drop";
  EXPECT_NEAR(*detection.time_s, expected, kPeriod);
}

TEST(YankMonitor, AxisSelectsAComponent) {
  const auto ramp_x = [](double t) { return Eigen::Vector3d(t > 0.1 ? 2000.0 * (t - 0.1) : 0.0, 0, 0); };
  YankMonitor on_y = armed(json{{"max_yank_n_per_s", 400}, {"axis", "y"}});
  EXPECT_FALSE(run_profile(on_y, ramp_x, every(kPeriod), 0.5).time_s.has_value());
  YankMonitor on_x = armed(json{{"max_yank_n_per_s", 400}, {"axis", "x"}});
  EXPECT_TRUE(run_profile(on_x, ramp_x, every(kPeriod), 0.5).time_s.has_value());
}

TEST(YankMonitor, NoFalseAlarmOnNoiseOnly) {
  // 60 s at 1 kHz, σ = 2 N per axis on a static 392 N: σ_yank = σ √(T/(4τ³)) ≈ 15.8 N/s per axis at
  // 10 Hz. A threshold of 8 σ_yank √3 ≈ 219 N/s on the norm must never fire.
  const double tau = time_constant_s(10.0);
  const double sigma = 2.0;
  const double sigma_yank = sigma * std::sqrt(kPeriod / (4.0 * tau * tau * tau));
  const double threshold = 8.0 * sigma_yank * std::sqrt(3.0);
  std::mt19937 rng(99);
  std::normal_distribution<double> noise(0.0, sigma);
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", threshold}});
  double peak = 0.0;
  for (int k = 0; k < 60000; ++k) {
    const Eigen::Vector3d force(noise(rng), noise(rng), -392.0 + noise(rng));
    const Verdict verdict = monitor.on_wrench(at(k * kPeriod), force, Eigen::Vector3d::Zero());
    ASSERT_FALSE(verdict.fired()) << "false alarm at t=" << k * kPeriod << ": " << verdict.message;
    peak = std::max(peak, monitor.yank_n_per_s().norm());
  }
  EXPECT_GT(peak, 2.0 * sigma_yank) << "the noise did reach the differentiator";
  EXPECT_LT(peak, threshold);
}

TEST(YankMonitor, DropoutFiresSensorStale) {
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}, {"max_sample_age_s", 0.02}});
  for (int k = 0; k <= 100; ++k) {
    ASSERT_FALSE(monitor.on_wrench(at(k * kPeriod), Eigen::Vector3d(0, 0, -392), Eigen::Vector3d::Zero()).fired());
  }
  // No sample after t = 0.1 s: the host wakes at next_deadline().
  const auto deadline = monitor.next_deadline();
  ASSERT_TRUE(deadline.has_value());
  EXPECT_FALSE(monitor.on_time(*deadline - std::chrono::nanoseconds(1)).fired());
  const Verdict verdict = monitor.on_time(*deadline);
  EXPECT_EQ(verdict.code, kCodeSensorStale);
  EXPECT_NEAR(testing::since_t0(*deadline), 0.12, 2e-9);
}

TEST(YankMonitor, DuplicateAndBackwardsStampsAreRejected) {
  // A duplicate would be a zero-length interval and a backwards stamp a negative one: a naive
  // differentiator divides by them. Both must be ignored without firing.
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  ASSERT_FALSE(monitor.on_wrench(at(0.000), Eigen::Vector3d(0, 0, -392), zero).fired());
  ASSERT_FALSE(monitor.on_wrench(at(0.001), Eigen::Vector3d(0, 0, -392), zero).fired());
  EXPECT_FALSE(monitor.on_wrench(at(0.001), Eigen::Vector3d(0, 0, 0), zero).fired());
  EXPECT_FALSE(monitor.on_wrench(at(0.0005), Eigen::Vector3d(0, 0, 0), zero).fired());
  EXPECT_FALSE(monitor.on_wrench(at(0.002), Eigen::Vector3d(0, 0, -392), zero).fired());
  EXPECT_EQ(monitor.rejected_samples(), 2u);
  EXPECT_TRUE(monitor.yank_n_per_s().isZero(1e-9));
}

TEST(YankMonitor, NaNFiresSensorInvalid) {
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  EXPECT_EQ(monitor.on_wrench(at(0.0), Eigen::Vector3d(NAN, 0, 0), Eigen::Vector3d::Zero()).code, kCodeSensorInvalid);
}

TEST(YankMonitor, ResetStartsAFreshRun) {
  YankMonitor monitor = armed(json{{"max_yank_n_per_s", 400}});
  ASSERT_TRUE(run_profile(monitor, [](double t) { return Eigen::Vector3d(5000.0 * t, 0, 0); }, every(kPeriod), 0.5)
                  .time_s.has_value());
  ASSERT_TRUE(monitor.fired());
  ASSERT_TRUE(monitor.reset(json{{"max_yank_n_per_s", 400}}, kT0 + milliseconds(1000)).ok());
  EXPECT_FALSE(monitor.fired());
  EXPECT_EQ(monitor.rejected_samples(), 0u);
  // A static force far from where the last run ended: no start-up transient.
  for (int k = 0; k < 100; ++k) {
    ASSERT_FALSE(monitor.on_wrench(at(1.0 + k * kPeriod), Eigen::Vector3d(0, 0, -392), Eigen::Vector3d::Zero()).fired());
  }
}

}  // namespace
}  // namespace rigger::monitor
