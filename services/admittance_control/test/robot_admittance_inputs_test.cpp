// RobotAdmittance: its inputs and faults (stale and invalid wrenches, the tool's weight, frames, selected
// axes), its modes and references, and its configuration.
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
