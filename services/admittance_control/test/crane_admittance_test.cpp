#include "crane_admittance.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/base/config.hpp"
#include "robot_admittance.hpp"

namespace rigger::control {
namespace {

constexpr double kH = 0.02;  // 50 Hz
const Seconds kDt{kH};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

CraneAdmittanceConfig bare_config() {
  CraneAdmittanceConfig c;
  c.deadband_n.setZero();
  c.force_filter_cutoff_hz = 0.0;
  c.max_speed_mps.setConstant(10.0);
  c.max_acceleration_mps2.setConstant(1e6);
  c.robot_velocity_feedforward = 0.0;
  c.gain_transition_time = Seconds(0.0);
  return c;
}

CraneAdmittance enabled_law(const CraneAdmittanceConfig& c) {
  CraneAdmittance law(c);
  law.set_enabled(true);
  return law;
}

CraneInput pull(const Eigen::Vector3d& force_on_robot_world_n, double age_s = 0.005) {
  CraneInput in;
  in.force_on_robot_world_n = force_on_robot_world_n;
  in.force_age = Seconds(age_s);
  return in;
}

TEST(CraneAdmittance, MovesTheWayTheRobotPullsTheLoadWithTheFirstOrderResponse) {
  // The robot pulls the load towards +x: the load pulls the wrist towards -x (what the sensor
  // measures), and the crane must follow towards +x at F / D after M / D seconds.
  CraneAdmittanceConfig c = bare_config();
  CraneAdmittance law = enabled_law(c);
  const double f = 45.0, m = c.gains.mass_kg.x(), d = c.gains.damping_ns_per_m.x();
  for (int k = 1; k <= 200; ++k) {
    const CraneOutput out = law.step(kDt, pull(Eigen::Vector3d(-f, 0.0, 0.0)));
    ASSERT_EQ(out.status.state, CraneState::kActive);
    ASSERT_NEAR(out.velocity_world_mps.x(), f / d * (1.0 - std::exp(-k * kH * d / m)), 1e-12);
    ASSERT_EQ(out.velocity_world_mps.y(), 0.0);
  }
  // And along y the other way round.
  CraneAdmittance other = enabled_law(c);
  CraneOutput out;
  for (int k = 0; k < 300; ++k) out = other.step(kDt, pull(Eigen::Vector3d(0.0, 30.0, 0.0)));
  EXPECT_NEAR(out.velocity_world_mps.y(), -30.0 / c.gains.damping_ns_per_m.y(), 1e-6);
  EXPECT_NEAR(out.force_applied_n.y(), -30.0, 1e-12);
}

TEST(CraneAdmittance, TakesTheWristForceRotatedIntoTheWorld) {
  // The sensor is turned 90 deg about z (sensor x = world y) and carries a 2 kg tool. It reads the
  // tool weight plus the load pulling the wrist along sensor -x, i.e. world -y: the crane goes +y.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const ToolModel tool{2.0, Eigen::Vector3d(0.0, 0.0, 0.05)};
  const Eigen::Vector3d g(0.0, 0.0, -9.81);
  Wrench measured;
  measured.force_n = Eigen::Vector3d(-40.0, 0.0, 0.0) + R.transpose() * (2.0 * g);
  measured.torque_nm = tool.center_of_mass_m.cross(R.transpose() * (2.0 * g));
  const Wrench contact_world = rotate(R, compensate_tool_weight(measured, R, tool, g));
  CraneAdmittanceConfig c = bare_config();
  CraneAdmittance law = enabled_law(c);
  CraneOutput out;
  for (int k = 0; k < 300; ++k) out = law.step(kDt, pull(contact_world.force_n));
  EXPECT_NEAR(out.velocity_world_mps.y(), 40.0 / c.gains.damping_ns_per_m.y(), 1e-6);
  EXPECT_NEAR(out.velocity_world_mps.x(), 0.0, 1e-9);
  EXPECT_EQ(out.velocity_world_mps.z(), 0.0);  // the tool weight did not leak into the hoist
}

TEST(CraneAdmittance, HoistFollowsVerticalForceOnlyWhenSelected) {
  CraneAdmittanceConfig c = bare_config();
  CraneAdmittance horizontal_only = enabled_law(c);
  c.selected_axes = {true, true, true};
  CraneAdmittance with_hoist = enabled_law(c);
  // The robot pushes the load down: the load pushes the wrist up (+z); the hoist should lower.
  CraneOutput a, b;
  for (int k = 0; k < 300; ++k) {
    a = horizontal_only.step(kDt, pull(Eigen::Vector3d(0.0, 0.0, 60.0)));
    b = with_hoist.step(kDt, pull(Eigen::Vector3d(0.0, 0.0, 60.0)));
  }
  EXPECT_EQ(a.velocity_world_mps.z(), 0.0);
  EXPECT_NEAR(b.velocity_world_mps.z(), -60.0 / c.gains.damping_ns_per_m.z(), 1e-6);
  const auto axes = to_crane_axes(b.velocity_world_mps);
  EXPECT_GT(axes[2], 0.0);  // rope length grows: positive hoist velocity lowers
  EXPECT_EQ(axes[0], b.velocity_world_mps.x());
  EXPECT_EQ(axes[1], b.velocity_world_mps.y());
}

TEST(CraneAdmittance, FeedsTheRobotsVelocityForwardAndUsesAMeasuredRopeOffset) {
  CraneAdmittanceConfig c = bare_config();
  c.robot_velocity_feedforward = 0.8;
  c.rope_offset_gain_per_s = 0.5;
  CraneAdmittance law = enabled_law(c);
  CraneInput in = pull(Eigen::Vector3d::Zero());
  in.robot_velocity_world_mps = Eigen::Vector3d(0.1, -0.05, 0.02);
  CraneOutput out = law.step(kDt, in);
  EXPECT_NEAR((out.velocity_world_mps - Eigen::Vector3d(0.08, -0.04, 0.0)).norm(), 0.0, 1e-12);  // hoist off
  in.rope_offset_world_m = Eigen::Vector3d(0.04, 0.0, 0.3);  // z is ignored
  out = law.step(kDt, in);
  EXPECT_NEAR((out.velocity_world_mps - Eigen::Vector3d(0.08 + 0.02, -0.04, 0.0)).norm(), 0.0, 1e-12);
}

TEST(CraneAdmittance, DeadbandSpeedAndAccelerationLimits) {
  CraneAdmittanceConfig c = bare_config();
  c.deadband_n = Eigen::Vector3d(1.0, 1.0, 3.0);
  c.max_speed_mps = Eigen::Vector3d(0.5, 0.2, 0.2);
  c.max_acceleration_mps2 = Eigen::Vector3d(0.5, 0.5, 0.3);
  CraneAdmittance law = enabled_law(c);
  CraneOutput out;
  for (int k = 0; k < 100; ++k) {
    out = law.step(kDt, pull(Eigen::Vector3d(0.9, -0.9, 0.0)));
    ASSERT_TRUE(out.velocity_world_mps.isZero(0.0));
  }
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int k = 0; k < 500; ++k) {
    out = law.step(kDt, pull(Eigen::Vector3d(-600.0, -600.0, 0.0)));  // 2 m/s unlimited, both axes
    ASSERT_LE((out.velocity_world_mps - previous).cwiseAbs().maxCoeff(), 0.5 * kH + 1e-9);
    ASSERT_LE(out.velocity_world_mps.y(), 0.2 + 1e-9);
    previous = out.velocity_world_mps;
  }
  EXPECT_TRUE(out.status.velocity_limited);
  EXPECT_NEAR(out.velocity_world_mps.x(), 0.5, 1e-9);  // independent drives: each at its own limit
  EXPECT_NEAR(out.velocity_world_mps.y(), 0.2, 1e-9);
}

TEST(CraneAdmittance, StaleAndInvalidInputGiveZeroAndAFault) {
  CraneAdmittance law = enabled_law(bare_config());
  for (int k = 0; k < 50; ++k) law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  CraneOutput out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0), 0.15));
  EXPECT_EQ(out.status.fault, CraneFault::kForceStale);
  EXPECT_FALSE(out.status.fault_latched);
  EXPECT_TRUE(out.velocity_world_mps.isZero(0.0));
  EXPECT_EQ(law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0))).status.state, CraneState::kActive);

  out = law.step(kDt, pull(Eigen::Vector3d(kNaN, 0.0, 0.0)));
  EXPECT_EQ(out.status.fault, CraneFault::kForceNotFinite);
  EXPECT_EQ(to_string(out.status.fault), "FORCE_NOT_FINITE");
  EXPECT_TRUE(out.status.fault_latched);
  EXPECT_TRUE(law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0))).velocity_world_mps.isZero(0.0));
  law.set_enabled(true);  // acknowledge
  EXPECT_EQ(law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0))).status.state, CraneState::kActive);

  EXPECT_EQ(law.step(kDt, pull(Eigen::Vector3d(0.0, 2500.0, 0.0))).status.fault, CraneFault::kForceImplausible);
  law.set_enabled(true);
  CraneInput bad_feedforward = pull(Eigen::Vector3d::Zero());
  bad_feedforward.robot_velocity_world_mps.x() = kNaN;
  EXPECT_EQ(law.step(kDt, bad_feedforward).status.fault, CraneFault::kInputInvalid);
  law.set_enabled(true);
  EXPECT_EQ(law.step(Seconds(0.5), pull(Eigen::Vector3d::Zero())).status.fault, CraneFault::kTimeStepInvalid);
}

TEST(CraneAdmittance, DisabledIsZeroAndDisablingRampsDown) {
  CraneAdmittanceConfig c = bare_config();
  c.max_acceleration_mps2.setConstant(0.5);
  CraneAdmittance law(c);
  CraneOutput out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  EXPECT_EQ(out.status.state, CraneState::kDisabled);
  EXPECT_TRUE(out.velocity_world_mps.isZero(0.0));
  law.set_enabled(true);
  for (int k = 0; k < 300; ++k) out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  ASSERT_NEAR(out.velocity_world_mps.x(), 0.1, 1e-6);
  law.set_enabled(false);
  double previous = out.velocity_world_mps.x();
  for (int k = 0; k < 100 && out.status.state != CraneState::kDisabled; ++k) {
    out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
    EXPECT_LE(previous - out.velocity_world_mps.x(), 0.5 * kH + 1e-9);
    previous = out.velocity_world_mps.x();
  }
  EXPECT_EQ(out.status.state, CraneState::kDisabled);
  EXPECT_TRUE(out.velocity_world_mps.isZero(0.0));
}

// Disabled (a pause, a lost commander), the crane brakes at stop_deceleration_mps2, per axis.
TEST(CraneAdmittance, DisablingRampsDownAtTheStopDeceleration) {
  CraneAdmittanceConfig c = bare_config();
  c.max_acceleration_mps2.setConstant(0.5);
  c.stop_deceleration_mps2 = Eigen::Vector3d(1.0, 1.0, 0.6);
  CraneAdmittance law(c);
  law.set_enabled(true);
  CraneOutput out;
  for (int k = 0; k < 300; ++k) out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  ASSERT_NEAR(out.velocity_world_mps.x(), 0.1, 1e-6);
  law.set_enabled(false);
  int steps = 0;
  for (; steps < 100 && out.status.state != CraneState::kDisabled; ++steps) {
    const double previous = out.velocity_world_mps.x();
    out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
    EXPECT_NEAR(previous - out.velocity_world_mps.x(), std::min(previous, 1.0 * kH), 1e-9);
  }
  EXPECT_NEAR(steps, 0.1 / (1.0 * kH), 1.0);  // 100 ms, where max_acceleration_mps2 would take 200
  EXPECT_TRUE(out.velocity_world_mps.isZero(0.0));
}

TEST(CraneAdmittance, GainChangesAreBlendedAndInvalidOnesRefused) {
  CraneAdmittanceConfig c = bare_config();
  c.gain_transition_time = Seconds(1.0);
  CraneAdmittance law = enabled_law(c);
  CraneOutput out;
  for (int k = 0; k < 300; ++k) out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  CraneGains lighter = law.current_gains();
  lighter.damping_ns_per_m.x() = 150.0;
  ASSERT_TRUE(law.set_gains(lighter).accepted);
  const double before = out.velocity_world_mps.x();
  out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  EXPECT_TRUE(out.status.gains_blending);
  EXPECT_LT(std::abs(out.velocity_world_mps.x() - before), 1e-5);
  for (int k = 0; k < 1000; ++k) out = law.step(kDt, pull(Eigen::Vector3d(-30.0, 0.0, 0.0)));
  EXPECT_NEAR(out.velocity_world_mps.x(), 30.0 / 150.0, 1e-6);
  lighter.mass_kg.y() = -1.0;
  const RequestResult refused = law.set_gains(lighter);
  EXPECT_FALSE(refused.accepted);
  EXPECT_NE(refused.reason.find("gains/mass_kg/1"), std::string::npos) << refused.reason;
}

TEST(CraneAdmittance, ConstructorRefusesABadConfiguration) {
  CraneAdmittanceConfig c;
  c.robot_velocity_feedforward = 1.5;
  try {
    CraneAdmittance law(c);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/robot_velocity_feedforward");
  }
  c = CraneAdmittanceConfig{};
  c.max_acceleration_mps2.z() = 0.0;
  EXPECT_THROW(CraneAdmittance{c}, ConfigError);
}

}  // namespace
}  // namespace rigger::control
