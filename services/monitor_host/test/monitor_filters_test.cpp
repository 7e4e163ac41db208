#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "monitor_filters.hpp"

namespace rigger::monitor {
namespace {

constexpr double kE = 2.718281828459045;

// Sample times with spacing jittered uniformly in [0.2 T, 1.8 T].
std::vector<double> jittered_times(double period_s, double end_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> spacing(0.2 * period_s, 1.8 * period_s);
  std::vector<double> times{0.0};
  while (times.back() < end_s) times.push_back(times.back() + spacing(rng));
  return times;
}

TEST(LowPass3, TimeConstantFromCutoff) { EXPECT_NEAR(time_constant_s(10.0), 1.0 / (20.0 * M_PI), 1e-15); }

TEST(LowPass3, StartsAtTheFirstSample) {
  LowPass3 filter(0.01);
  EXPECT_EQ(filter.update(Eigen::Vector3d(1, 2, 3), 0.0), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(filter.update(Eigen::Vector3d(1, 2, 3), 0.001).isApprox(Eigen::Vector3d(1, 2, 3), 1e-15));
}

TEST(LowPass3, RampIsExactAtIrregularSamples) {
  // x = r t from t = 0, y(0) = 0: y(t) = r (t − τ (1 − e^(−t/τ))), whatever the spacing.
  const double tau = 0.01;
  const double r = 250.0;
  LowPass3 filter(tau);
  const auto times = jittered_times(0.001, 0.2, 7);
  double previous = 0.0;
  for (const double t : times) {
    const double y = filter.update(Eigen::Vector3d(r * t, -r * t, 0.0), t - previous).x();
    previous = t;
    EXPECT_NEAR(y, r * (t - tau * (1.0 - std::exp(-t / tau))), 1e-10) << "t=" << t;
  }
}

TEST(LowPass3, StepBetweenSamplesActsAtTheMidpoint) {
  // A step of 1 between samples t = 0 and t = T is a ramp over [0, T]; after it, the output is
  // the continuous step response from T/2 to within O((T/τ)²).
  const double tau = 0.01;
  const double period = 0.001;
  LowPass3 filter(tau);
  filter.update(Eigen::Vector3d::Zero(), 0.0);
  for (int k = 1; k <= 50; ++k) {
    const double y = filter.update(Eigen::Vector3d::Ones(), period).x();
    const double t = k * period;
    EXPECT_NEAR(y, 1.0 - std::exp(-(t - period / 2) / tau), 1e-3) << k;
  }
}

TEST(LowPass3, TinySpacingIsStable) {
  LowPass3 filter(0.01);
  filter.update(Eigen::Vector3d::Zero(), 0.0);
  const double y = filter.update(Eigen::Vector3d::Ones(), 1e-9).x();
  // A jump within 1 ns moves the output by about (dt/τ)/2.
  EXPECT_NEAR(y, 0.5e-7, 1e-12);
  EXPECT_TRUE(std::isfinite(y));
}

TEST(YankEstimator, RampYankAtIrregularSamples) {
  // Force ramp of slope r from t = 0: yank = r (1 − e^(−u)(1 + u)), u = t/τ.
  const double tau = time_constant_s(10.0);
  const double r = 1000.0;
  YankEstimator estimator(tau);
  const auto times = jittered_times(0.001, 0.3, 11);
  double previous = 0.0;
  for (const double t : times) {
    const double yank = estimator.update(Eigen::Vector3d(0, 0, r * t), t - previous).z();
    previous = t;
    const double u = t / tau;
    EXPECT_NEAR(yank, r * (1.0 - std::exp(-u) * (1.0 + u)), 1e-3 * r) << "t=" << t;
  }
}

TEST(YankEstimator, StepGivesAPulsePeakingAtSOverETau) {
  const double tau = time_constant_s(10.0);
  const double period = 0.001;
  const double step = 50.0;
  YankEstimator estimator(tau);
  estimator.update(Eigen::Vector3d::Zero(), 0.0);
  double peak = 0.0;
  double peak_time = 0.0;
  for (int k = 1; k <= 200; ++k) {
    const double yank = estimator.update(Eigen::Vector3d(step, 0, 0), period).x();
    if (yank > peak) {
      peak = yank;
      peak_time = k * period;
    }
  }
  EXPECT_NEAR(peak, step / (kE * tau), 0.01 * step / (kE * tau));
  EXPECT_NEAR(peak_time, tau + period / 2, period);
  EXPECT_NEAR(estimator.yank().x(), 0.0, 1e-3 * peak) << "the pulse decays back to zero";
}

TEST(YankEstimator, NoiseMatchesTheAnalyticStandardDeviation) {
  // White force noise σ per axis at period T: σ_yank ≈ σ √(T / (4 τ³)).
  const double tau = time_constant_s(10.0);
  const double period = 0.001;
  const double sigma = 2.0;
  YankEstimator estimator(tau);
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, sigma);
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
  const int warmup = 1000;
  const int samples = 20000;
  for (int k = 0; k < warmup + samples; ++k) {
    const Eigen::Vector3d yank = estimator.update(Eigen::Vector3d(noise(rng), noise(rng), noise(rng)), period);
    if (k >= warmup) sum_sq += yank.cwiseProduct(yank);
  }
  const double expected = sigma * std::sqrt(period / (4.0 * tau * tau * tau));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(std::sqrt(sum_sq[axis] / samples), expected, 0.1 * expected) << "axis " << axis;
  }
}

}  // namespace
}  // namespace rigger::monitor
