// RobotAdmittance: the law's dynamics (first and second order responses, saturation, deadband, the
// force filter, gain changes, limits).
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/base/config.hpp"
#include "robot_admittance.hpp"
#include "robot_admittance_test_support.hpp"

namespace rigger::control {
namespace {

using namespace admittance_test;

struct FirstOrderFit {
  double final_value = 0.0;
  double time_constant = 0.0;
};

// Fits v(t) = v_inf (1 - exp(-t / tau)): v_inf is the settled tail, tau the least-squares slope of
// ln(1 - v / v_inf) against t over the informative part of the rise (2 % to 98 %).
FirstOrderFit fit_first_order(const std::vector<double>& t, const std::vector<double>& v) {
  FirstOrderFit fit;
  fit.final_value = v.back();
  double stt = 0.0, sty = 0.0, st = 0.0, sy = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double r = v[i] / fit.final_value;
    if (r < 0.02 || r > 0.98) continue;
    const double y = std::log(1.0 - r);
    stt += t[i] * t[i];
    sty += t[i] * y;
    st += t[i];
    sy += y;
    ++n;
  }
  const double slope = (n * sty - st * sy) / (n * stt - st * st);
  fit.time_constant = -1.0 / slope;
  return fit;
}

struct StepCase {
  int axis;
  double mass;
  double damping;
  double force;
};

class FirstOrderStep : public ::testing::TestWithParam<StepCase> {};

TEST_P(FirstOrderStep, TimeConstantIsMassOverDampingWithinOnePercent) {
  const StepCase p = GetParam();
  RobotAdmittanceConfig c = bare_config();
  c.gains.mass[p.axis] = p.mass;
  c.gains.damping[p.axis] = p.damping;
  RobotAdmittance law = active_law(c);
  const double tau = p.mass / p.damping;
  std::vector<double> t, v;
  const int steps = static_cast<int>(std::ceil(15.0 * tau / kH));
  for (int k = 1; k <= steps; ++k) {
    const AdmittanceOutput out = law.step(kDt, sample(axis_value(p.axis, p.force)), kUpright, {});
    ASSERT_EQ(out.status.state, AdmittanceState::kActive);
    t.push_back(k * kH);
    v.push_back(out.twist.stacked()[p.axis]);
    for (int other = 0; other < 6; ++other) {
      if (other != p.axis) {
        ASSERT_EQ(out.twist.stacked()[other], 0.0);
      }
    }
  }
  const FirstOrderFit fit = fit_first_order(t, v);
  EXPECT_NEAR(fit.time_constant, tau, 0.01 * tau);
  EXPECT_NEAR(fit.final_value, p.force / p.damping, 0.01 * std::abs(p.force / p.damping));
  // And pointwise against v(t) = F/D (1 - exp(-t D/M)): exact for a force held over each step.
  for (std::size_t i = 0; i < v.size(); ++i)
    ASSERT_NEAR(v[i], p.force / p.damping * (1.0 - std::exp(-t[i] / tau)), 1e-9) << "t=" << t[i];
  std::printf("[ fit      ] axis %d: M/D = %.5f s, fitted tau = %.5f s (%.4f %%)\n", p.axis, tau, fit.time_constant,
              100.0 * (fit.time_constant - tau) / tau);
}

INSTANTIATE_TEST_SUITE_P(Axes, FirstOrderStep,
                         ::testing::Values(StepCase{0, 10.0, 100.0, 20.0}, StepCase{1, 5.0, 250.0, -40.0},
                                           StepCase{2, 2.0, 100.0, 15.0}, StepCase{3, 0.5, 10.0, 2.0},
                                           StepCase{5, 0.2, 10.0, -1.0}));

TEST(SecondOrderStep, SettlesAtForceOverStiffnessAlongTheAnalyticResponse) {
  RobotAdmittanceConfig c = bare_config();
  const double m = 10.0, d = 60.0, k = 400.0, f = 20.0;
  c.gains.mass[0] = m;
  c.gains.damping[0] = d;
  c.gains.stiffness[0] = k;
  RobotAdmittance law = active_law(c);
  const double wn = std::sqrt(k / m), z = d / (2.0 * std::sqrt(k * m)), wd = wn * std::sqrt(1.0 - z * z);
  double position = 0.0;
  double peak = 0.0;
  for (int i = 1; i <= 2500; ++i) {  // 5 s, about 13 time constants 2M/D
    const double v = law.step(kDt, sample(axis_value(0, f)), kUpright, {}).twist.linear_mps.x();
    const double t = i * kH;
    // Velocity of the underdamped step response from rest: F / (M wd) e^(-z wn t) sin(wd t).
    ASSERT_NEAR(v, f / (m * wd) * std::exp(-z * wn * t) * std::sin(wd * t), 1e-9) << "t=" << t;
    position += v * kH;  // what a robot executing the commands travels
    peak = std::max(peak, position);
  }
  EXPECT_NEAR(position, f / k, 0.01 * f / k);
  const double overshoot = std::exp(-z * kPi / std::sqrt(1.0 - z * z));
  EXPECT_NEAR(peak, f / k * (1.0 + overshoot), 0.01 * f / k);
}

TEST(Saturation, VelocityIsLimitedPerAxisAndInNormWithItsDirectionKept) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_velocity << 0.2, 0.3, 0.3, 0.5, 0.5, 0.5;
  c.limits.max_linear_speed_mps = 0.25;
  RobotAdmittance law = active_law(c);
  Vector6d w = Vector6d::Zero();
  w << 500.0, 500.0, 0.0, 0.0, 0.0, 0.0;  // 5 m/s along x and y unlimited
  AdmittanceOutput out;
  for (int i = 0; i < 1000; ++i) {
    out = law.step(kDt, sample(w), kUpright, {});
    ASSERT_LE(std::abs(out.twist.linear_mps.x()), 0.2 + 1e-9);
    ASSERT_LE(out.twist.linear_mps.norm(), 0.25 + 1e-9);
  }
  EXPECT_TRUE(out.status.velocity_limited);
  EXPECT_NEAR(out.twist.linear_mps.x(), out.twist.linear_mps.y(), 1e-12);
  EXPECT_NEAR(out.twist.linear_mps.norm(), 0.25 * std::min(1.0, 0.2 / (0.25 / std::sqrt(2.0))), 1e-9);
  // Anti-windup: once the force goes away the command leaves the limit at once, it does not
  // first unwind a stored 5 m/s.
  const AdmittanceOutput released = law.step(kDt, sample(Vector6d::Zero()), kUpright, {});
  EXPECT_LT(released.twist.linear_mps.norm(), out.twist.linear_mps.norm());
}

TEST(Saturation, AccelerationIsLimitedPerStep) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_acceleration << 1.0, 1.0, 1.0, 2.0, 2.0, 2.0;
  RobotAdmittance law = active_law(c);
  Vector6d w = Vector6d::Zero();
  w << 80.0, 0.0, 0.0, 0.0, 0.0, 5.0;  // unlimited: 0.8 m/s and 0.5 rad/s after ~0.1 s
  Vector6d previous = Vector6d::Zero();
  bool limited = false;
  for (int i = 0; i < 1000; ++i) {
    const AdmittanceOutput out = law.step(kDt, sample(w), kUpright, {});
    const Vector6d now = out.twist.stacked();
    ASSERT_LE(std::abs(now[0] - previous[0]), 1.0 * kH + 1e-9);
    ASSERT_LE(std::abs(now[5] - previous[5]), 2.0 * kH + 1e-9);
    limited = limited || out.status.acceleration_limited;
    previous = now;
  }
  EXPECT_TRUE(limited);
  EXPECT_NEAR(previous[0], 0.8, 1e-3);  // still reaches the admittance's steady state
}

TEST(Deadband, ForceBelowItDoesNothingAndAboveItIsReducedByIt) {
  RobotAdmittanceConfig c = bare_config();
  c.deadband << 3.0, 3.0, 3.0, 0.2, 0.2, 0.2;
  RobotAdmittance law = active_law(c);
  for (int i = 0; i < 200; ++i) {
    const AdmittanceOutput out = law.step(kDt, sample(axis_value(1, -2.9)), kUpright, {});
    ASSERT_TRUE(out.twist.stacked().isZero(0.0));
  }
  AdmittanceOutput out;
  for (int i = 0; i < 2000; ++i) out = law.step(kDt, sample(axis_value(1, -8.0)), kUpright, {});
  EXPECT_NEAR(out.twist.linear_mps.y(), -(8.0 - 3.0) / c.gains.damping[1], 1e-6);
  EXPECT_NEAR(out.wrench_applied.force_n.y(), -5.0, 1e-12);
}

TEST(ForceFilter, FollowsTheFirstOrderStepAndAttenuatesVibration) {
  RobotAdmittanceConfig c = bare_config();
  c.force_filter_cutoff_hz = 5.0;
  RobotAdmittance law = active_law(c);
  for (int i = 1; i <= 200; ++i) {
    const AdmittanceOutput out = law.step(kDt, sample(axis_value(0, 10.0)), kUpright, {});
    ASSERT_NEAR(out.wrench_applied.force_n.x(), 10.0 * (1.0 - std::exp(-2.0 * kPi * 5.0 * i * kH)), 1e-9);
  }
  // A 100 Hz vibration of 10 N is attenuated about 20 times; a 0.5 Hz push passes.
  auto amplitude_after_filter = [&](double frequency_hz) {
    RobotAdmittance fresh = active_law(c);
    double peak = 0.0;
    for (int i = 1; i <= 4000; ++i) {
      const double f = 10.0 * std::sin(2.0 * kPi * frequency_hz * i * kH);
      const double filtered = fresh.step(kDt, sample(axis_value(2, f)), kUpright, {}).wrench_applied.force_n.z();
      if (i > 2000) peak = std::max(peak, std::abs(filtered));
    }
    return peak;
  };
  EXPECT_LT(amplitude_after_filter(100.0), 10.0 / 15.0);
  EXPECT_GT(amplitude_after_filter(0.5), 9.5);
}

TEST(GainChange, IsBlendedWithoutAJumpInTheOutput) {
  auto run = [](Seconds transition, std::vector<double>& velocity) {
    RobotAdmittanceConfig c = bare_config();
    c.gain_transition_time = transition;
    RobotAdmittance law = active_law(c);
    for (int i = 0; i < 1500; ++i) law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});  // settled at 0.2
    AdmittanceGains softer = law.current_gains();
    softer.damping[0] = 50.0;
    softer.mass[0] = 2.0;
    EXPECT_TRUE(law.set_gains(softer).accepted);
    for (int i = 0; i < 1000; ++i) {
      const AdmittanceOutput out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
      velocity.push_back(out.twist.linear_mps.x());
      if (transition.count() > 0.0 && i < 200) {
        EXPECT_TRUE(out.status.gains_blending);
      }
    }
    EXPECT_FALSE(law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {}).status.gains_blending);
    EXPECT_EQ(law.current_gains().damping[0], 50.0);
    return law.current_gains();
  };
  std::vector<double> instant, blended;
  run(Seconds(0.0), instant);
  run(Seconds(0.5), blended);
  auto first_step = [](const std::vector<double>& v) { return std::abs(v[0] - 0.2); };
  auto largest_change_of_step = [](const std::vector<double>& v) {
    double largest = 0.0;
    for (std::size_t i = 2; i < v.size(); ++i) largest = std::max(largest, std::abs((v[i] - v[i - 1]) - (v[i - 1] - v[i - 2])));
    return largest;
  };
  // Applied at once, the output's slope jumps from 0 to (F - D v) / M; blended, it starts from 0.
  EXPECT_GT(first_step(instant), 1e-3);
  EXPECT_LT(first_step(blended), 1e-5);
  EXPECT_LT(largest_change_of_step(blended), 0.05 * first_step(instant));
  EXPECT_NEAR(blended.back(), 20.0 / 50.0, 1e-4);  // and it still ends at the new steady state
  EXPECT_NEAR(instant.back(), 20.0 / 50.0, 1e-4);
}

TEST(GainChange, AddingStiffnessAfterFreeGuidingHoldsTheCurrentPosition) {
  RobotAdmittanceConfig c = bare_config();
  c.gain_transition_time = Seconds(0.2);
  RobotAdmittance law = active_law(c);
  for (int i = 0; i < 500; ++i) law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});  // pushed ~0.2 m
  for (int i = 0; i < 1000; ++i) law.step(kDt, sample(Vector6d::Zero()), kUpright, {});   // comes to rest
  AdmittanceGains stiff = law.current_gains();
  stiff.stiffness[0] = 500.0;
  ASSERT_TRUE(law.set_gains(stiff).accepted);
  double travel = 0.0;
  for (int i = 0; i < 2000; ++i) travel += law.step(kDt, sample(Vector6d::Zero()), kUpright, {}).twist.linear_mps.x() * kH;
  EXPECT_NEAR(travel, 0.0, 1e-6);  // the spring is anchored here, not where guiding started
  // And the new spring works: a push now settles at F / K.
  double displacement = 0.0;
  for (int i = 0; i < 3000; ++i) displacement += law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {}).twist.linear_mps.x() * kH;
  EXPECT_NEAR(displacement, 20.0 / 500.0, 1e-3);
}

// The target again (admittance_control passes every command's gains) changes nothing: the blend under way is
// not restarted from where it is, so it ends on time.
TEST(GainChange, TheCurrentTargetAgainLeavesTheBlendAlone) {
  RobotAdmittanceConfig c = bare_config();
  c.gain_transition_time = Seconds(0.2);
  RobotAdmittance law = active_law(c);
  AdmittanceGains softer = law.current_gains();
  softer.damping[0] = 50.0;
  ASSERT_TRUE(law.set_gains(softer).accepted);
  for (int i = 0; i < 50; ++i) law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});  // half the blend
  ASSERT_NE(law.current_gains().damping[0], 50.0);
  ASSERT_TRUE(law.set_gains(softer).accepted);
  for (int i = 0; i < 51; ++i) law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});  // the other half
  EXPECT_EQ(law.current_gains().damping[0], 50.0) << "the same target restarted the blend";
}

TEST(GainChange, InvalidGainsAreRefusedAndChangeNothing) {
  RobotAdmittance law = active_law(bare_config());
  const AdmittanceGains before = law.target_gains();
  AdmittanceGains bad = before;
  bad.damping[2] = 0.0;  // undamped free axis: refused
  RequestResult r = law.set_gains(bad);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.reason.find("gains/damping/2"), std::string::npos) << r.reason;
  bad = before;
  bad.mass[4] = kNaN;
  EXPECT_FALSE(law.set_gains(bad).accepted);
  bad = before;
  bad.stiffness[0] = -1.0;
  EXPECT_FALSE(law.set_gains(bad).accepted);
  EXPECT_EQ(law.target_gains().damping, before.damping);
  EXPECT_EQ(law.target_gains().mass, before.mass);
  EXPECT_EQ(law.target_gains().stiffness, before.stiffness);
}

TEST(Limits, ALowerVelocityLimitIsReachedAtTheAccelerationLimit) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_acceleration.setConstant(1.0);
  RobotAdmittance law = active_law(c);
  AdmittanceOutput out;
  for (int i = 0; i < 1000; ++i) out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
  MotionLimits slower = c.limits;
  slower.max_velocity[0] = 0.1;
  ASSERT_TRUE(law.set_limits(slower).accepted);
  double previous = out.twist.linear_mps.x();
  for (int i = 0; i < 200; ++i) {
    out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
    ASSERT_GE(out.twist.linear_mps.x(), previous - 1.0 * kH - 1e-9);
    previous = out.twist.linear_mps.x();
  }
  EXPECT_NEAR(out.twist.linear_mps.x(), 0.1, 1e-9);
  slower.max_acceleration[1] = 0.0;
  const RequestResult refused = law.set_limits(slower);
  EXPECT_FALSE(refused.accepted);
  EXPECT_NE(refused.reason.find("limits/max_acceleration/1"), std::string::npos) << refused.reason;
}

}  // namespace
}  // namespace rigger::control
