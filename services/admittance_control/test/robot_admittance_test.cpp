#include "robot_admittance.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/base/config.hpp"

namespace rigger::control {
namespace {

constexpr double kH = 0.002;  // 500 Hz
const Seconds kDt{kH};
const Eigen::Quaterniond kUpright = Eigen::Quaterniond::Identity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// No deadband, no filter, limits out of the way, gains applied at once: the bare law.
RobotAdmittanceConfig bare_config() {
  RobotAdmittanceConfig c;
  c.deadband.setZero();
  c.force_filter_cutoff_hz = 0.0;
  c.reference_filter_cutoff_hz = 0.0;
  c.limits.max_velocity.setConstant(100.0);
  c.limits.max_linear_speed_mps = 0.0;
  c.limits.max_angular_speed_radps = 0.0;
  c.limits.max_acceleration.setConstant(1e6);
  c.gain_transition_time = Seconds(0.0);
  return c;
}

WrenchSample sample(const Vector6d& wrench, double age_s = 0.001) {
  return WrenchSample{Wrench::from_stacked(wrench), Seconds(age_s)};
}

Vector6d axis_value(int axis, double value) {
  Vector6d v = Vector6d::Zero();
  v[axis] = value;
  return v;
}

RobotAdmittance active_law(const RobotAdmittanceConfig& config) {
  RobotAdmittance law(config);
  law.set_mode(AdmittanceMode::kRobot);
  return law;
}

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

TEST(StaleWrench, GivesZeroOutputAndAFaultThatClearsWithFreshData) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_acceleration.setConstant(1.0);
  RobotAdmittance law = active_law(c);
  for (int i = 0; i < 300; ++i) law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
  AdmittanceOutput out = law.step(kDt, sample(axis_value(0, 20.0), 0.021), kUpright, {});
  EXPECT_EQ(out.status.state, AdmittanceState::kFault);
  EXPECT_EQ(out.status.fault, AdmittanceFault::kWrenchStale);
  EXPECT_EQ(to_string(out.status.fault), "WRENCH_STALE");
  EXPECT_FALSE(out.status.fault_latched);
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  // A sample from the future is no better.
  EXPECT_EQ(law.step(kDt, sample(axis_value(0, 20.0), -0.5), kUpright, {}).status.fault, AdmittanceFault::kWrenchStale);
  // Fresh again: active, restarting from rest under the acceleration limit (no resumed 0.2 m/s).
  out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
  EXPECT_EQ(out.status.state, AdmittanceState::kActive);
  EXPECT_LE(out.twist.linear_mps.x(), 1.0 * kH + 1e-9);
}

TEST(InvalidInput, NaNInfAndAbsurdWrenchesLatchAFaultInsteadOfCountingAsZeroForce) {
  struct Case {
    Vector6d wrench;
    AdmittanceFault fault;
  };
  const std::vector<Case> cases{
      {axis_value(0, kNaN), AdmittanceFault::kWrenchNotFinite},
      {axis_value(4, kInf), AdmittanceFault::kWrenchNotFinite},
      {axis_value(1, -1500.0), AdmittanceFault::kWrenchImplausible},
      {axis_value(5, 150.0), AdmittanceFault::kWrenchImplausible},
  };
  for (const Case& k : cases) {
    RobotAdmittanceConfig c = bare_config();
    RobotAdmittance law = active_law(c);
    law.set_reference_source(ReferenceSource::kJoystick);
    ReferenceInput joystick{ReferenceSource::kJoystick, Twist{Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d::Zero()},
                            ControlFrame::kBase, Seconds(0.0)};
    EXPECT_GT(law.step(kDt, sample(Vector6d::Zero()), kUpright, joystick).twist.linear_mps.x(), 0.0);
    AdmittanceOutput out = law.step(kDt, sample(k.wrench), kUpright, joystick);
    EXPECT_EQ(out.status.fault, k.fault) << k.wrench.transpose();
    EXPECT_TRUE(out.status.fault_latched);
    // Zero force would still follow the joystick; a fault commands zero.
    EXPECT_TRUE(out.twist.stacked().isZero(0.0));
    // Latched: good samples do not clear it...
    out = law.step(kDt, sample(Vector6d::Zero()), kUpright, joystick);
    EXPECT_EQ(out.status.fault, k.fault);
    EXPECT_TRUE(out.twist.stacked().isZero(0.0));
    // ...an explicit mode command does.
    law.set_mode(AdmittanceMode::kRobot);
    out = law.step(kDt, sample(Vector6d::Zero()), kUpright, joystick);
    EXPECT_EQ(out.status.state, AdmittanceState::kActive);
    EXPECT_GT(out.twist.linear_mps.x(), 0.0);
  }
}

TEST(InvalidInput, BadOrientationReferenceAndTimeStepAreFaults) {
  RobotAdmittance law = active_law(bare_config());
  const Eigen::Quaterniond nan_q(kNaN, 0.0, 0.0, 0.0);
  EXPECT_EQ(law.step(kDt, sample(Vector6d::Zero()), nan_q, {}).status.fault, AdmittanceFault::kOrientationInvalid);
  law.set_mode(AdmittanceMode::kRobot);
  const Eigen::Quaterniond scaled(2.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(law.step(kDt, sample(Vector6d::Zero()), scaled, {}).status.fault, AdmittanceFault::kOrientationInvalid);
  law.set_mode(AdmittanceMode::kRobot);
  law.set_reference_source(ReferenceSource::kVisualServo);
  ReferenceInput bad{ReferenceSource::kVisualServo, Twist{Eigen::Vector3d(kNaN, 0, 0), Eigen::Vector3d::Zero()},
                     ControlFrame::kBase, Seconds(0.0)};
  const AdmittanceOutput ref_fault = law.step(kDt, sample(Vector6d::Zero()), kUpright, bad);
  EXPECT_EQ(ref_fault.status.fault, AdmittanceFault::kReferenceInvalid);
  EXPECT_TRUE(ref_fault.status.fault_latched);
  law.set_mode(AdmittanceMode::kRobot);
  for (double dt : {0.0, -0.002, kNaN, 0.051}) {
    const AdmittanceOutput out = law.step(Seconds(dt), sample(axis_value(0, 10.0)), kUpright, {});
    EXPECT_EQ(out.status.fault, AdmittanceFault::kTimeStepInvalid) << dt;
    EXPECT_FALSE(out.status.fault_latched);
    EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  }
  EXPECT_EQ(law.step(kDt, sample(axis_value(0, 10.0)), kUpright, {}).status.state, AdmittanceState::kActive);
}

// OFF commands nothing, whatever the loop's timing: a late iteration on a busy machine once turned into
// a zero twist that preempted the robot's own point-to-point motion (seen on a three-host cell).
TEST(RobotAdmittance, OffStaysOffOnALateOrInvalidStep) {
  RobotAdmittance law(bare_config());
  for (double dt : {0.051, 0.5, 0.0, -0.002, kNaN}) {
    const AdmittanceOutput out = law.step(Seconds(dt), sample(axis_value(0, 10.0)), kUpright, {});
    EXPECT_EQ(out.status.state, AdmittanceState::kOff) << dt;
    EXPECT_EQ(out.status.fault, AdmittanceFault::kNone) << dt;
  }
}

TEST(ToolWeight, CompensationMatchesHandComputedWrenchWithTheToolRotated) {
  // Tool 2 kg, centre of mass (0.01, 0.02, 0.05) m in the sensor frame, sensor turned 90 deg about
  // base x: sensor y points up, so gravity (0, 0, -19.62) N reads (0, -19.62, 0) in the sensor frame
  // and its torque c x F = (0.05 * 19.62, 0, -0.01 * 19.62).
  ToolModel tool{2.0, Eigen::Vector3d(0.01, 0.02, 0.05)};
  const Eigen::Matrix3d R = Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Wrench measured;
  measured.force_n = Eigen::Vector3d(0.0, -19.62, 0.0);
  measured.torque_nm = Eigen::Vector3d(0.981, 0.0, -0.1962);
  const Wrench zero = compensate_tool_weight(measured, R, tool, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_NEAR(zero.force_n.norm(), 0.0, 1e-12);
  EXPECT_NEAR(zero.torque_nm.norm(), 0.0, 1e-12);
  // With a contact force of 5 N along sensor x on top, and a bias, only the contact force remains.
  Wrench bias;
  bias.force_n = Eigen::Vector3d(0.5, -0.25, 1.0);
  measured.force_n += Eigen::Vector3d(5.0, 0.0, 0.0) + bias.force_n;
  const Wrench contact = compensate_tool_weight(measured, R, tool, Eigen::Vector3d(0, 0, -9.81), bias);
  EXPECT_NEAR((contact.force_n - Eigen::Vector3d(5.0, 0.0, 0.0)).norm(), 0.0, 1e-12);
}

TEST(ToolWeight, TheLawHoldsStillUnderTheToolsOwnWeightInAnyOrientation) {
  RobotAdmittanceConfig c = bare_config();
  c.tool = ToolModel{2.5, Eigen::Vector3d(0.0, 0.01, 0.06)};
  const Eigen::Vector3d g(0.0, 0.0, -9.81);
  for (const Eigen::Quaterniond& q :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitY())),
        Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()))}) {
    RobotAdmittance law = active_law(c);
    // What the sensor reads: the tool's weight, written out independently of the law's code.
    const Eigen::Vector3d f_sensor = q.toRotationMatrix().transpose() * (2.5 * g);
    Vector6d reading;
    reading << f_sensor, c.tool.center_of_mass_m.cross(f_sensor);
    AdmittanceOutput out;
    for (int i = 0; i < 100; ++i) out = law.step(kDt, sample(reading), q, {});
    EXPECT_LT(out.twist.stacked().norm(), 1e-12) << q.coeffs().transpose();
    // Without compensation the same reading would drive the robot down.
    RobotAdmittanceConfig uncompensated = bare_config();
    RobotAdmittance naive = active_law(uncompensated);
    for (int i = 0; i < 100; ++i) out = naive.step(kDt, sample(reading), q, {});
    EXPECT_LT(out.twist.linear_mps.z(), -0.01);
  }
}

TEST(Frames, BaseFrameRotatesTheSensorForceAndToolFrameKeepsIt) {
  // Sensor turned 90 deg about base z: sensor x is base y.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  RobotAdmittanceConfig c = bare_config();
  RobotAdmittance base = active_law(c);
  c.frame = ControlFrame::kTool;
  RobotAdmittance tool = active_law(c);
  AdmittanceOutput in_base, in_tool;
  for (int i = 0; i < 2000; ++i) {
    in_base = base.step(kDt, sample(axis_value(0, 13.0)), q, {});
    in_tool = tool.step(kDt, sample(axis_value(0, 13.0)), q, {});
  }
  EXPECT_EQ(in_base.frame, ControlFrame::kBase);
  EXPECT_NEAR(in_base.twist.linear_mps.y(), 0.13, 1e-6);
  EXPECT_NEAR(in_base.twist.linear_mps.x(), 0.0, 1e-9);
  EXPECT_EQ(in_tool.frame, ControlFrame::kTool);
  EXPECT_NEAR(in_tool.twist.linear_mps.x(), 0.13, 1e-6);
  EXPECT_NEAR(in_tool.twist.linear_mps.y(), 0.0, 1e-9);
  EXPECT_NEAR((in_base.wrench_base.force_n - Eigen::Vector3d(0.0, 13.0, 0.0)).norm(), 0.0, 1e-9);
}

TEST(Frames, ForceThroughTheTcpMakesNoRotation) {
  // A 10 N push along x at the TCP, 0.12 m along sensor z: the sensor reads the torque r x f =
  // (0, 1.2, 0) N m, which about the TCP is zero.
  RobotAdmittanceConfig c = bare_config();
  c.tcp_in_sensor_m = Eigen::Vector3d(0.0, 0.0, 0.12);
  RobotAdmittance law = active_law(c);
  Vector6d reading;
  reading << 10.0, 0.0, 0.0, 0.0, 1.2, 0.0;
  AdmittanceOutput out;
  for (int i = 0; i < 500; ++i) out = law.step(kDt, sample(reading), kUpright, {});
  EXPECT_GT(out.twist.linear_mps.x(), 0.05);
  EXPECT_NEAR(out.twist.angular_radps.norm(), 0.0, 1e-12);
  // Without the offset the same reading is a torque about the sensor and turns the tool.
  RobotAdmittance at_sensor = active_law(bare_config());
  for (int i = 0; i < 500; ++i) out = at_sensor.step(kDt, sample(reading), kUpright, {});
  EXPECT_GT(out.twist.angular_radps.y(), 0.05);
}

TEST(SelectedAxes, DeselectedAxesIgnoreForceButPassTheReference) {
  RobotAdmittanceConfig c = bare_config();
  c.selected_axes = {true, false, true, true, true, true};
  RobotAdmittance law = active_law(c);
  law.set_reference_source(ReferenceSource::kJoystick);
  const ReferenceInput joystick{ReferenceSource::kJoystick,
                                Twist{Eigen::Vector3d(0.0, 0.05, 0.0), Eigen::Vector3d::Zero()}, ControlFrame::kBase,
                                Seconds(0.0)};
  Vector6d w = Vector6d::Zero();
  w << 10.0, 30.0, 0.0, 0.0, 0.0, 0.0;
  AdmittanceOutput out;
  for (int i = 0; i < 2000; ++i) out = law.step(kDt, sample(w), kUpright, joystick);
  EXPECT_NEAR(out.twist.linear_mps.x(), 0.1, 1e-6);
  EXPECT_NEAR(out.twist.linear_mps.y(), 0.05, 1e-12);  // the 30 N on y is ignored
  EXPECT_EQ(out.wrench_applied.force_n.y(), 0.0);
}

TEST(Modes, OffIsZeroAndSwitchingOffWhileMovingRampsDownAtTheAccelerationLimit) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_acceleration.setConstant(1.0);
  RobotAdmittance law(c);
  AdmittanceOutput out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
  EXPECT_EQ(out.status.state, AdmittanceState::kOff);
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  // In OFF the wrench is not even looked at: no stale fault without a sensor.
  EXPECT_EQ(law.step(kDt, sample(Vector6d::Zero(), 10.0), kUpright, {}).status.state, AdmittanceState::kOff);
  law.set_mode(AdmittanceMode::kRobotAndCrane);
  for (int i = 0; i < 1000; ++i) out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
  ASSERT_NEAR(out.twist.linear_mps.x(), 0.2, 1e-6);
  law.set_mode(AdmittanceMode::kOff);
  double previous = out.twist.linear_mps.x();
  int stopping_steps = 0;
  for (int i = 0; i < 200; ++i) {
    out = law.step(kDt, sample(axis_value(0, 20.0)), kUpright, {});
    if (out.status.state == AdmittanceState::kOff) break;
    EXPECT_EQ(out.status.state, AdmittanceState::kStopping);
    EXPECT_NEAR(previous - out.twist.linear_mps.x(), 1.0 * kH, 1e-9);
    previous = out.twist.linear_mps.x();
    ++stopping_steps;
  }
  EXPECT_EQ(out.status.state, AdmittanceState::kOff);
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  EXPECT_NEAR(stopping_steps, 0.2 / (1.0 * kH), 1.5);
}

// A stop brakes at stop_deceleration (a pause, a lost commander), harder than the motion accelerates; a
// stop_deceleration below the acceleration limit never makes the stop slower than max_acceleration.
TEST(Modes, SwitchingOffRampsDownAtTheStopDecelerationButNeverSlowerThanTheAccelerationLimit) {
  for (const double stop : {2.0, 0.25}) {
    RobotAdmittanceConfig c = bare_config();
    c.limits.max_acceleration.setConstant(1.0);
    c.limits.stop_deceleration.setConstant(stop);
    RobotAdmittance law(c);
    law.set_mode(AdmittanceMode::kRobot);
    AdmittanceOutput out;
    for (int i = 0; i < 1000; ++i) out = law.step(kDt, sample(axis_value(1, 20.0)), kUpright, {});
    ASSERT_NEAR(out.twist.linear_mps.y(), 0.2, 1e-6);
    law.set_mode(AdmittanceMode::kOff);
    int stopping_steps = 0;
    while (out.status.state != AdmittanceState::kOff && stopping_steps < 1000) {
      const double previous = out.twist.linear_mps.y();
      out = law.step(kDt, sample(axis_value(1, 20.0)), kUpright, {});
      if (out.status.state == AdmittanceState::kStopping) {
        EXPECT_NEAR(previous - out.twist.linear_mps.y(), std::max(stop, 1.0) * kH, 1e-9) << stop;
      }
      ++stopping_steps;
    }
    EXPECT_NEAR(stopping_steps, 0.2 / (std::max(stop, 1.0) * kH), 1.5) << stop;
  }
}

TEST(Reference, JoystickIsAFeedForwardTheForceAddsTo) {
  RobotAdmittanceConfig c = bare_config();
  c.limits.max_acceleration.setConstant(1.0);
  RobotAdmittance law = active_law(c);
  law.set_reference_source(ReferenceSource::kJoystick);
  const ReferenceInput joystick{ReferenceSource::kJoystick,
                                Twist{Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, 0.2)},
                                ControlFrame::kBase, Seconds(0.01)};
  AdmittanceOutput out;
  double previous = 0.0;
  for (int i = 0; i < 1000; ++i) {
    out = law.step(kDt, sample(Vector6d::Zero()), kUpright, joystick);
    ASSERT_LE(out.twist.linear_mps.x() - previous, 1.0 * kH + 1e-9);  // the step in reference is ramped
    previous = out.twist.linear_mps.x();
  }
  EXPECT_EQ(out.status.reference, ReferenceStatus::kApplied);
  EXPECT_NEAR(out.twist.linear_mps.x(), 0.1, 1e-6);
  EXPECT_NEAR(out.twist.angular_radps.z(), 0.2, 1e-6);
  for (int i = 0; i < 1000; ++i) out = law.step(kDt, sample(axis_value(0, -6.0)), kUpright, joystick);
  EXPECT_NEAR(out.twist.linear_mps.x(), 0.1 - 6.0 / 100.0, 1e-6);  // pushing back slows it down
}

TEST(Reference, StepsAreSmoothedByTheReferenceFilter) {
  RobotAdmittanceConfig c = bare_config();
  c.reference_filter_cutoff_hz = 3.0;
  RobotAdmittance law = active_law(c);
  law.set_reference_source(ReferenceSource::kVisualServo);
  const ReferenceInput step{ReferenceSource::kVisualServo,
                            Twist{Eigen::Vector3d(0.0, 0.1, 0.0), Eigen::Vector3d::Zero()}, ControlFrame::kBase,
                            Seconds(0.0)};
  for (int i = 1; i <= 500; ++i) {
    const AdmittanceOutput out = law.step(kDt, sample(Vector6d::Zero()), kUpright, step);
    ASSERT_NEAR(out.twist.linear_mps.y(), 0.1 * (1.0 - std::exp(-2.0 * kPi * 3.0 * i * kH)), 1e-12);
  }
  // Losing the reference fades it out the same way instead of stopping dead.
  const AdmittanceOutput after_loss = law.step(kDt, sample(Vector6d::Zero()), kUpright, ReferenceInput{});
  EXPECT_NEAR(after_loss.twist.linear_mps.y(), 0.1 * std::exp(-2.0 * kPi * 3.0 * kH), 1e-6);
}

TEST(Reference, OtherSourcesAndStaleReferencesAreNotApplied) {
  RobotAdmittance law = active_law(bare_config());
  const Twist fast{Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d::Zero()};
  AdmittanceOutput out = law.step(kDt, sample(Vector6d::Zero()), kUpright,
                                  ReferenceInput{ReferenceSource::kJoystick, fast, ControlFrame::kBase, Seconds(0)});
  EXPECT_EQ(out.status.reference, ReferenceStatus::kNotSelected);
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  law.set_reference_source(ReferenceSource::kVisualServo);
  out = law.step(kDt, sample(Vector6d::Zero()), kUpright,
                 ReferenceInput{ReferenceSource::kJoystick, fast, ControlFrame::kBase, Seconds(0)});
  EXPECT_EQ(out.status.reference, ReferenceStatus::kOtherSource);
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
  out = law.step(kDt, sample(Vector6d::Zero()), kUpright,
                 ReferenceInput{ReferenceSource::kVisualServo, fast, ControlFrame::kBase, Seconds(0.3)});
  EXPECT_EQ(out.status.reference, ReferenceStatus::kStale);
  EXPECT_EQ(out.status.state, AdmittanceState::kActive);  // not a fault: the law still yields to force
  EXPECT_TRUE(out.twist.stacked().isZero(0.0));
}

TEST(Reference, BaseFrameReferenceIsRotatedIntoTheToolFrame) {
  RobotAdmittanceConfig c = bare_config();
  c.frame = ControlFrame::kTool;
  RobotAdmittance law = active_law(c);
  law.set_reference_source(ReferenceSource::kVisualServo);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));  // sensor y = base -x
  const ReferenceInput ref{ReferenceSource::kVisualServo,
                           Twist{Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d::Zero()}, ControlFrame::kBase,
                           Seconds(0)};
  AdmittanceOutput out;
  for (int i = 0; i < 1000; ++i) out = law.step(kDt, sample(Vector6d::Zero()), q, ref);
  EXPECT_NEAR((out.twist.linear_mps - Eigen::Vector3d(0.0, -0.1, 0.0)).norm(), 0.0, 1e-6);
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

TEST(Config, ConstructorNamesTheBrokenField) {
  RobotAdmittanceConfig c;
  c.gains.damping[3] = -1.0;
  try {
    RobotAdmittance law(c);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/gains/damping/3");
    EXPECT_NE(std::string(e.what()).find("rx"), std::string::npos) << e.what();
  }
  c = RobotAdmittanceConfig{};
  c.wrench_timeout = Seconds(0.0);
  EXPECT_THROW(RobotAdmittance{c}, ConfigError);
  EXPECT_NO_THROW(RobotAdmittance{RobotAdmittanceConfig{}});
}

TEST(Names, ModesAndSourcesRoundTrip) {
  for (auto m : {AdmittanceMode::kOff, AdmittanceMode::kRobot, AdmittanceMode::kRobotAndCrane})
    EXPECT_EQ(admittance_mode_from_string(to_string(m)), m);
  for (auto s : {ReferenceSource::kNone, ReferenceSource::kJoystick, ReferenceSource::kVisualServo})
    EXPECT_EQ(reference_source_from_string(to_string(s)), s);
  EXPECT_EQ(control_frame_from_string("tool"), ControlFrame::kTool);
  EXPECT_FALSE(admittance_mode_from_string("robot").has_value());
}

}  // namespace
}  // namespace rigger::control
