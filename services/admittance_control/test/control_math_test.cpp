#include "control_math.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace rigger::control {
namespace {

TEST(DiscretiseAxis, FirstOrderMatchesTheClosedForm) {
  // K = 0: v(k+1) = exp(-h D/M) v(k) + (1 - exp(-h D/M)) / D * f, and x advances by the integral.
  const double m = 10.0, d = 100.0, h = 0.002;
  const double tau = m / d;
  const double decay = std::exp(-h / tau);
  const AxisDiscretisation a = discretise_axis(m, d, 0.0, h);
  EXPECT_NEAR(a.phi(0, 0), 1.0, 1e-14);
  EXPECT_NEAR(a.phi(0, 1), tau * (1.0 - decay), 1e-14);
  EXPECT_NEAR(a.phi(1, 0), 0.0, 1e-14);
  EXPECT_NEAR(a.phi(1, 1), decay, 1e-14);
  EXPECT_NEAR(a.gamma(1), (1.0 - decay) / d, 1e-14);
  EXPECT_NEAR(a.gamma(0), (h - tau * (1.0 - decay)) / d, 1e-14);
}

TEST(DiscretiseAxis, SecondOrderStepMatchesTheAnalyticResponse) {
  // Underdamped M x'' + D x' + K x = F from rest:
  // x(t) = F/K (1 - e^(-z wn t) (cos(wd t) + z / sqrt(1 - z^2) sin(wd t))).
  const double m = 2.0, d = 8.0, k = 200.0, f = 10.0, h = 0.004;
  const double wn = std::sqrt(k / m), z = d / (2.0 * std::sqrt(k * m)), wd = wn * std::sqrt(1.0 - z * z);
  ASSERT_LT(z, 1.0);
  const AxisDiscretisation a = discretise_axis(m, d, k, h);
  Eigen::Vector2d s = Eigen::Vector2d::Zero();
  for (int i = 1; i <= 500; ++i) {
    s = a.phi * s + a.gamma * f;
    const double t = i * h;
    const double expected =
        f / k * (1.0 - std::exp(-z * wn * t) * (std::cos(wd * t) + z / std::sqrt(1.0 - z * z) * std::sin(wd * t)));
    ASSERT_NEAR(s(0), expected, 1e-10) << "t=" << t;
  }
}

TEST(DiscretiseAxis, StaysAccurateNearZeroStiffnessAndCriticalDamping) {
  // The closed forms lose precision here (1/K, 1/(wn - z wn)); the augmented exponential does not.
  const double m = 10.0, d = 100.0, h = 0.002;
  const AxisDiscretisation free_axis = discretise_axis(m, d, 0.0, h);
  const AxisDiscretisation tiny_spring = discretise_axis(m, d, 1e-9, h);
  EXPECT_NEAR((free_axis.phi - tiny_spring.phi).norm(), 0.0, 1e-12);
  EXPECT_NEAR((free_axis.gamma - tiny_spring.gamma).norm(), 0.0, 1e-12);
  const double k_critical = d * d / (4.0 * m);
  const AxisDiscretisation below = discretise_axis(m, d, k_critical * (1.0 - 1e-9), h);
  const AxisDiscretisation at = discretise_axis(m, d, k_critical, h);
  EXPECT_NEAR((below.phi - at.phi).norm(), 0.0, 1e-9);
  EXPECT_TRUE(at.phi.allFinite() && at.gamma.allFinite());
}

TEST(CachedAxisDiscretisation, RecomputesOnlyWhenAParameterChanges) {
  CachedAxisDiscretisation cache;
  const AxisDiscretisation first = cache.get(10.0, 100.0, 0.0, 0.002);
  EXPECT_EQ(cache.get(10.0, 100.0, 0.0, 0.002).phi, first.phi);
  const AxisDiscretisation other = cache.get(10.0, 50.0, 0.0, 0.002);
  EXPECT_NE(other.phi(1, 1), first.phi(1, 1));
  EXPECT_NEAR(other.phi(1, 1), std::exp(-0.002 * 50.0 / 10.0), 1e-14);
}

TEST(LowPass, StepResponseHasTheCutOffTimeConstant) {
  const double fc = 5.0, h = 0.002;
  const double alpha = low_pass_alpha(fc, h);
  double y = 0.0;
  for (int i = 1; i <= 200; ++i) {
    y += alpha * (1.0 - y);
    ASSERT_NEAR(y, 1.0 - std::exp(-2.0 * kPi * fc * i * h), 1e-12);
  }
  EXPECT_EQ(low_pass_alpha(0.0, h), 1.0);
}

TEST(Deadband, IsContinuousAndSymmetric) {
  EXPECT_EQ(apply_deadband(2.9, 3.0), 0.0);
  EXPECT_EQ(apply_deadband(-3.0, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(apply_deadband(5.0, 3.0), 2.0);
  EXPECT_DOUBLE_EQ(apply_deadband(-5.0, 3.0), -2.0);
  EXPECT_NEAR(apply_deadband(3.0 + 1e-9, 3.0), 1e-9, 1e-15);
  EXPECT_DOUBLE_EQ(apply_deadband(4.0, 0.0), 4.0);
}

TEST(LimitPreservingDirection, ScalesUniformlyToTheTightestLimit) {
  Eigen::Vector3d v(1.0, 0.5, 0.0);
  EXPECT_TRUE(limit_preserving_direction(v, Eigen::Vector3d(0.25, 1.0, 1.0)));
  EXPECT_NEAR(v.x(), 0.25, 1e-15);
  EXPECT_NEAR(v.y(), 0.125, 1e-15);  // direction kept
  Eigen::Vector3d w(0.3, 0.4, 0.0);   // norm 0.5
  EXPECT_TRUE(limit_preserving_direction(w, Eigen::Vector3d::Constant(1.0), 0.25));
  EXPECT_NEAR(w.norm(), 0.25, 1e-15);
  EXPECT_NEAR(w.x() / w.y(), 0.75, 1e-12);
  Eigen::Vector3d inside(0.1, -0.1, 0.1);
  EXPECT_FALSE(limit_preserving_direction(inside, Eigen::Vector3d::Constant(1.0), 1.0));
  EXPECT_EQ(inside, Eigen::Vector3d(0.1, -0.1, 0.1));
}

TEST(LimitPreservingDirection, ZeroLimitLocksOnlyThatAxis) {
  Eigen::Vector3d v(0.1, 0.2, 0.3);
  EXPECT_TRUE(limit_preserving_direction(v, Eigen::Vector3d(1.0, 1.0, 0.0)));
  EXPECT_EQ(v, Eigen::Vector3d(0.1, 0.2, 0.0));
}

TEST(LimitRate, StepsAtMostTheRateTimesDt) {
  const Eigen::Vector3d previous(0.0, 0.0, 0.0);
  Eigen::Vector3d target(1.0, 1.0, 0.0);
  EXPECT_TRUE(limit_rate(previous, target, Eigen::Vector3d(1.0, 2.0, 1.0), 0.01));
  EXPECT_NEAR(target.x(), 0.01, 1e-15);
  EXPECT_NEAR(target.y(), 0.01, 1e-15);  // same direction as the requested change
  Eigen::Vector3d near_target(0.005, 0.0, 0.0);
  EXPECT_FALSE(limit_rate(previous, near_target, Eigen::Vector3d::Constant(1.0), 0.01));
}

TEST(RampToZero, ReachesZeroAtTheRate) {
  // 0.5 to go on y at 0.125 per step: four steps (a fifth may mop up rounding).
  Eigen::Vector3d v(0.375, -0.5, 0.0);
  int calls = 0;
  bool moving = true;
  while (moving && calls < 100) {
    const Eigen::Vector3d before = v;
    moving = ramp_to_zero(v, Eigen::Vector3d::Constant(1.0), 0.125);
    ++calls;
    EXPECT_LE((v - before).cwiseAbs().maxCoeff(), 0.125 + 1e-15);
    EXPECT_NEAR(v.x() / (v.y() == 0.0 ? 1.0 : v.y()), v.y() == 0.0 ? 0.0 : -0.75, 1e-9);  // direction kept
  }
  EXPECT_GE(calls, 4);
  EXPECT_LE(calls, 5);
  EXPECT_TRUE(v.isZero(0.0));
}

TEST(IsFresh, RefusesOldFutureAndNaNAges) {
  const Seconds limit(0.1);
  EXPECT_TRUE(is_fresh(Seconds(0.05), limit));
  EXPECT_TRUE(is_fresh(Seconds(0.1), limit));
  EXPECT_FALSE(is_fresh(Seconds(0.1001), limit));
  EXPECT_FALSE(is_fresh(Seconds(-0.2), limit));
  EXPECT_FALSE(is_fresh(Seconds(std::numeric_limits<double>::quiet_NaN()), limit));
}

TEST(GainBlend, MovesSmoothlyAndEndsOnTarget) {
  GainBlend<Eigen::Vector2d> blend(Eigen::Vector2d(10.0, 100.0));
  blend.set_target(Eigen::Vector2d(20.0, 50.0), Seconds(1.0));
  EXPECT_TRUE(blend.blending());
  double previous = 10.0;
  double previous_step = 0.0;
  double largest_step = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double value = blend.advance(Seconds(0.01))(0);
    const double step = value - previous;
    EXPECT_GE(step, 0.0);  // monotonic
    EXPECT_LE(std::abs(step - previous_step), 0.0065);  // no kink (a linear ramp would jump by 0.1)
    largest_step = std::max(largest_step, step);
    previous = value;
    previous_step = step;
  }
  EXPECT_FALSE(blend.blending());
  EXPECT_EQ(blend.current(), Eigen::Vector2d(20.0, 50.0));
  EXPECT_NEAR(largest_step, 1.5 * 10.0 * 0.01, 1e-3);  // smoothstep's peak slope is 1.5
}

TEST(GainBlend, RetargetingMidwayStartsFromTheCurrentValue) {
  GainBlend<Eigen::Vector2d> blend(Eigen::Vector2d(0.0, 0.0));
  blend.set_target(Eigen::Vector2d(10.0, 10.0), Seconds(1.0));
  for (int i = 0; i < 50; ++i) blend.advance(Seconds(0.01));
  const Eigen::Vector2d midway = blend.current();
  blend.set_target(Eigen::Vector2d(0.0, 0.0), Seconds(1.0));
  EXPECT_EQ(blend.current(), midway);
  EXPECT_NEAR(blend.advance(Seconds(0.01))(0), midway(0), 0.01);  // a restart from 0 would jump by 5
  blend.set_target(Eigen::Vector2d(3.0, 3.0), Seconds(0.0));
  EXPECT_EQ(blend.current(), Eigen::Vector2d(3.0, 3.0));
  EXPECT_FALSE(blend.blending());
}

}  // namespace
}  // namespace rigger::control
