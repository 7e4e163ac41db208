#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "force_monitor.hpp"
#include "monitor_test_util.hpp"

namespace rigger::monitor {
namespace {

using nlohmann::json;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using testing::at;
using testing::every;
using testing::kT0;
using testing::run_profile;

constexpr double kPeriod = 0.001;  // 1 kHz wrench stream

ForceMonitor armed(const json& params) { return testing::armed<ForceMonitor>(params); }

TEST(ForceMonitor, StepDetectionDelayMatchesTheFirstOrderFilter) {
  // Step from 0 to S at t_s; limit L; the filtered force crosses L at t_s − τ ln(1 − L/S) and the
  // monitor fires one dwell later.
  const double cutoff_hz = 20.0;
  const double tau = 1.0 / (2.0 * M_PI * cutoff_hz);
  const double limit = 100.0;
  const double step = 150.0;
  const double dwell = 0.02;
  const double t_step = 0.3;
  ForceMonitor monitor = armed(json{{"max_force_n", limit}, {"dwell_s", dwell}, {"cutoff_hz", cutoff_hz}});
  const auto detection = run_profile(
      monitor, [&](double t) { return Eigen::Vector3d(0, 0, t >= t_step - 1e-9 ? -step : 0.0); }, every(kPeriod), 1.0);
  ASSERT_TRUE(detection.time_s.has_value());
  const double expected = t_step - tau * std::log(1.0 - limit / step) + dwell;
  EXPECT_NEAR(*detection.time_s, expected, kPeriod) << "expected " << expected;
  EXPECT_EQ(detection.verdict.code, kCodeForceLimit);
  EXPECT_GT(detection.verdict.value, limit);
  EXPECT_NE(detection.verdict.message.find("above the limit 100.0 N"), std::string::npos) << detection.verdict.message;
}

TEST(ForceMonitor, StepWithoutDwellAndOnAnAxis) {
  const double cutoff_hz = 50.0;
  const double tau = 1.0 / (2.0 * M_PI * cutoff_hz);
  for (const double step : {120.0, 200.0, 1000.0}) {
    ForceMonitor monitor =
        armed(json{{"max_force_n", 100}, {"dwell_s", 0}, {"cutoff_hz", cutoff_hz}, {"axis", "y"}});
    const auto detection = run_profile(
        monitor, [&](double t) { return Eigen::Vector3d(500.0, t >= 0.1 - 1e-9 ? step : 0.0, 0.0); }, every(kPeriod), 1.0);
    ASSERT_TRUE(detection.time_s.has_value()) << step;
    EXPECT_NEAR(*detection.time_s, 0.1 - tau * std::log(1.0 - 100.0 / step), kPeriod) << step;
  }
}

TEST(ForceMonitor, RampDetectionMatchesTheFilteredRamp) {
  // F = r (t − t_s) after t_s. The first-order-hold filter is exact for a ramp:
  // y(t') = r (t' − τ (1 − e^(−t'/τ))), so the monitor fires at the first sample after y = L.
  const double tau = 1.0 / (2.0 * M_PI * 20.0);
  const double r = 2000.0;
  const double limit = 100.0;
  const double t_s = 0.2;
  ForceMonitor monitor = armed(json{{"max_force_n", limit}, {"dwell_s", 0}});
  const auto detection = run_profile(
      monitor, [&](double t) { return Eigen::Vector3d(t > t_s ? r * (t - t_s) : 0.0, 0, 0); }, every(kPeriod), 1.0);
  ASSERT_TRUE(detection.time_s.has_value());
  const double crossing = testing::solve_increasing(
      [&](double t) { return r * (t - tau * (1.0 - std::exp(-t / tau))) - limit; }, 0.0, 1.0);
  EXPECT_GE(*detection.time_s, t_s + crossing - 1e-9);
  EXPECT_LE(*detection.time_s, t_s + crossing + kPeriod);
}

TEST(ForceMonitor, RampWithIrregularSampleSpacing) {
  const double tau = 1.0 / (2.0 * M_PI * 20.0);
  const double r = 2000.0;
  const double limit = 100.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(0.3 * kPeriod, 1.7 * kPeriod);
  std::vector<double> times{0.0};
  while (times.back() < 1.0) times.push_back(times.back() + jitter(rng));
  ForceMonitor monitor = armed(json{{"max_force_n", limit}, {"dwell_s", 0}});
  const auto detection = run_profile(
      monitor, [&](double t) { return Eigen::Vector3d(0, r * t, 0); },
      [&](int k) { return times[static_cast<std::size_t>(k)]; }, 0.99);
  ASSERT_TRUE(detection.time_s.has_value());
  const double crossing = testing::solve_increasing(
      [&](double t) { return r * (t - tau * (1.0 - std::exp(-t / tau))) - limit; }, 0.0, 1.0);
  EXPECT_GE(*detection.time_s, crossing - 1e-9);
  EXPECT_LE(*detection.time_s, crossing + detection.max_spacing_s);
}

TEST(ForceMonitor, NoFalseAlarmOnNoiseOnly) {
  // 60 s of 1 kHz Gaussian noise, σ = 2 N per axis, on a static 150 N load; limit 160 N, no dwell.
  // Filtered noise: σ √(T/(2τ)) ≈ 0.5 N per axis at 20 Hz, so 10 N of margin is 20 σ.
  std::mt19937 rng(1234);
  std::normal_distribution<double> noise(0.0, 2.0);
  ForceMonitor monitor = armed(json{{"max_force_n", 160}, {"dwell_s", 0}});
  double peak = 0.0;
  for (int k = 0; k < 60000; ++k) {
    const Eigen::Vector3d force(noise(rng), noise(rng), -150.0 + noise(rng));
    const Verdict verdict = monitor.on_wrench(at(k * kPeriod), force, Eigen::Vector3d::Zero());
    ASSERT_FALSE(verdict.fired()) << "false alarm at t=" << k * kPeriod << ": " << verdict.message;
    peak = std::max(peak, monitor.filtered_force_n().norm());
  }
  EXPECT_LT(peak, 153.0) << "filtered noise larger than expected";
  EXPECT_GT(peak, 150.5) << "the noise did reach the filter";
}

TEST(ForceMonitor, ASpikeShorterThanTheDwellDoesNotFire) {
  // 10 ms spike of 200 N over a 100 N limit: filtered above the limit for ~7 ms.
  const auto spike = [](double t) { return Eigen::Vector3d(0, 0, (t >= 0.1 - 1e-9 && t < 0.11 - 1e-9) ? 200.0 : 0.0); };
  ForceMonitor long_dwell = armed(json{{"max_force_n", 100}, {"dwell_s", 0.02}});
  EXPECT_FALSE(run_profile(long_dwell, spike, every(kPeriod), 0.5).time_s.has_value());
  ForceMonitor short_dwell = armed(json{{"max_force_n", 100}, {"dwell_s", 0.005}});
  EXPECT_TRUE(run_profile(short_dwell, spike, every(kPeriod), 0.5).time_s.has_value());
}

TEST(ForceMonitor, TorqueLimit) {
  ForceMonitor monitor = armed(json{{"max_torque_nm", 10}, {"dwell_s", 0}});
  const auto detection = run_profile(
      monitor, [](double) { return Eigen::Vector3d(0, 0, -500); }, every(kPeriod), 0.5,
      [](double t) { return Eigen::Vector3d(t > 0.1 ? 20.0 : 0.0, 0, 0); });
  ASSERT_TRUE(detection.time_s.has_value()) << "a torque step must fire, a large force must not";
  EXPECT_NE(detection.verdict.message.find("torque norm"), std::string::npos) << detection.verdict.message;
  EXPECT_NE(detection.verdict.message.find("above the limit 10.0 Nm"), std::string::npos);
}

TEST(ForceMonitor, RelativeLimitWatchesTheChangeFromTheStart) {
  // A 40 kg load hangs on the tool (392 N); the monitor should watch only new contact.
  const auto load_then_contact = [](double t) { return Eigen::Vector3d(0, 0, -392.0 + (t >= 0.2 - 1e-9 ? -60.0 : 0.0)); };
  ForceMonitor absolute = armed(json{{"max_force_n", 50}, {"dwell_s", 0}});
  const auto absolute_detection = run_profile(absolute, load_then_contact, every(kPeriod), 0.5);
  ASSERT_TRUE(absolute_detection.time_s.has_value());
  EXPECT_DOUBLE_EQ(*absolute_detection.time_s, 0.0) << "the static load alone exceeds an absolute limit";
  ForceMonitor relative = armed(json{{"max_force_n", 50}, {"dwell_s", 0}, {"relative", true}});
  const auto relative_detection = run_profile(relative, load_then_contact, every(kPeriod), 0.5);
  ASSERT_TRUE(relative_detection.time_s.has_value());
  EXPECT_GT(*relative_detection.time_s, 0.2);
  EXPECT_LT(*relative_detection.time_s, 0.25);
  EXPECT_NE(relative_detection.verdict.message.find("change of force"), std::string::npos);
}

TEST(ForceMonitor, DropoutFiresSensorStaleExactlyAtTheMaxAge) {
  ForceMonitor monitor = armed(json{{"max_force_n", 100}, {"max_sample_age_s", 0.05}});
  for (int k = 0; k <= 500; ++k) ASSERT_FALSE(monitor.on_wrench(at(k * kPeriod), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).fired());
  // The stream stops after t = 0.5 s.
  const Stamp last = at(0.5);
  EXPECT_EQ(monitor.next_deadline(), last + milliseconds(50) + nanoseconds(1));
  EXPECT_FALSE(monitor.on_time(last + milliseconds(50)).fired());
  const Verdict verdict = monitor.on_time(last + milliseconds(50) + nanoseconds(1));
  ASSERT_TRUE(verdict.fired());
  EXPECT_EQ(verdict.code, kCodeSensorStale);
  EXPECT_NEAR(verdict.value, 0.05, 1e-6);
  EXPECT_NE(verdict.message.find("no wrench sample for 0.050 s (allowed 0.050 s)"), std::string::npos) << verdict.message;
}

TEST(ForceMonitor, ALateSampleAfterAGapFiresSensorStale) {
  ForceMonitor monitor = armed(json{{"max_force_n", 100}, {"max_sample_age_s", 0.05}});
  ASSERT_FALSE(monitor.on_wrench(at(0.0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).fired());
  const Verdict verdict = monitor.on_wrench(at(0.08), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  ASSERT_TRUE(verdict.fired());
  EXPECT_EQ(verdict.code, kCodeSensorStale);
  EXPECT_NEAR(verdict.value, 0.08, 1e-9);
}

TEST(ForceMonitor, NoSampleAtAllSinceTheStartIsStale) {
  ForceMonitor monitor = armed(json{{"max_force_n", 100}});
  EXPECT_EQ(monitor.next_deadline(), kT0 + milliseconds(100) + nanoseconds(1));
  EXPECT_FALSE(monitor.on_time(kT0 + milliseconds(100)).fired());
  EXPECT_EQ(monitor.on_time(kT0 + milliseconds(101)).code, kCodeSensorStale);
}

TEST(ForceMonitor, ASampleFromBeforeTheStartDoesNotCountAsFresh) {
  ForceMonitor monitor = armed(json{{"max_force_n", 100}});
  ASSERT_FALSE(monitor.on_wrench(kT0 - milliseconds(500), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).fired());
  EXPECT_EQ(monitor.next_deadline(), kT0 + milliseconds(100) + nanoseconds(1));
}

TEST(ForceMonitor, NaNFiresSensorInvalid) {
  ForceMonitor monitor = armed(json{{"max_force_n", 100}});
  ASSERT_FALSE(monitor.on_wrench(at(0.0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).fired());
  const Verdict verdict = monitor.on_wrench(at(0.001), Eigen::Vector3d::Zero(), Eigen::Vector3d(0, NAN, 0));
  ASSERT_TRUE(verdict.fired());
  EXPECT_EQ(verdict.code, kCodeSensorInvalid);
  EXPECT_EQ(monitor.on_wrench(at(0.002), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).code, kCodeSensorInvalid)
      << "latched";
  ForceMonitor infinite = armed(json{{"max_force_n", 100}});
  EXPECT_EQ(infinite.on_wrench(at(0.0), Eigen::Vector3d(INFINITY, 0, 0), Eigen::Vector3d::Zero()).code, kCodeSensorInvalid);
}

TEST(ForceMonitor, DuplicateAndBackwardsStampsAreRejected) {
  ForceMonitor clean = armed(json{{"max_force_n", 1000}});
  ForceMonitor noisy = armed(json{{"max_force_n", 1000}});
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d force(0, 0, 10.0 * k);
    clean.on_wrench(at(k * kPeriod), force, zero);
    noisy.on_wrench(at(k * kPeriod), force, zero);
    // A duplicate with a wild value and a sample from the past: both must be ignored.
    EXPECT_FALSE(noisy.on_wrench(at(k * kPeriod), Eigen::Vector3d(0, 0, 5000), zero).fired());
    EXPECT_FALSE(noisy.on_wrench(at((k - 0.5) * kPeriod), Eigen::Vector3d(0, 0, 5000), zero).fired());
  }
  EXPECT_EQ(noisy.rejected_samples(), 40u);
  EXPECT_EQ(clean.rejected_samples(), 0u);
  EXPECT_TRUE(noisy.filtered_force_n().isApprox(clean.filtered_force_n(), 1e-12));
}

}  // namespace
}  // namespace rigger::monitor
