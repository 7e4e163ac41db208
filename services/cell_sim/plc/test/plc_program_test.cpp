#include "rigger/plc/plc_program.hpp"

#include <gtest/gtest.h>

#include <chrono>

#include "rigger/crane_protocol/testing.hpp"
#include "rigger/plc/kinematic_crane_axes.hpp"

namespace rigger::plc {
namespace {

using ::rigger::crane::testing::reference_limits;

using namespace std::chrono_literals;
using crane::CraneMode;
using crane::FaultCode;

PlcProgramConfig config() {
  PlcProgramConfig c;
  c.limits = reference_limits();
  return c;
}

// The program in a closed loop with an ideal crane, on program time only (no clocks).
class Harness {
 public:
  explicit Harness(const Eigen::Vector3d& start = {4.0, 2.5, 2.0}, double load_kg = 40.0,
                   const PlcProgramConfig& program_config = config())
      : program(program_config), axes(start, load_kg) {}

  /// Cycles for `duration` in steps of `dt`, the gateway heartbeat changing every cycle when
  /// `heartbeat_alive`.
  PlcOutputs run(std::chrono::nanoseconds duration, std::chrono::nanoseconds dt = 4ms) {
    PlcOutputs out;
    for (std::chrono::nanoseconds t{0}; t < duration; t += dt) {
      out = once(dt);
    }
    return out;
  }

  PlcOutputs once(std::chrono::nanoseconds dt = 4ms) {
    if (heartbeat_alive) {
      ++command.gateway_heartbeat;
    }
    PlcInputs in;
    in.command = command_valid ? std::optional<crane::CraneCommand>(command) : std::nullopt;
    in.gateway_heartbeat = command.gateway_heartbeat;
    in.measured = axes.read();
    const PlcOutputs out = program.cycle(in, dt);
    axes.apply_velocity(out.velocity_command_mps);
    axes.advance(dt);
    last = out;
    return out;
  }

  /// Enable and request external control with zero setpoints, until granted.
  void take_control() {
    command.control.enable = true;
    command.control.external_control_request = true;
    command.requested_mode = CraneMode::kExternalVelocity;
    command.velocity_mps.setZero();
    once();
    ASSERT_TRUE(last.status.flags.external_control_granted);
  }

  void pulse_reset() {
    command.control.reset = true;
    once();
    command.control.reset = false;
    once();
  }

  PlcProgram program;
  KinematicCraneAxes axes;
  crane::CraneCommand command;
  bool command_valid = true;
  bool heartbeat_alive = true;
  PlcOutputs last;
};

TEST(PlcProgram, IgnoresSetpointsWithoutEnable) {
  Harness h;
  h.command.control.external_control_request = true;
  h.command.requested_mode = CraneMode::kExternalVelocity;
  h.command.velocity_mps = {0.3, 0.0, 0.0};
  const auto out = h.run(500ms);
  EXPECT_FALSE(out.status.flags.enabled);
  EXPECT_FALSE(out.status.flags.external_control_granted);
  EXPECT_TRUE(out.velocity_command_mps.isZero());
  EXPECT_DOUBLE_EQ(h.axes.read().position_m.x(), 4.0);
  EXPECT_TRUE(out.status.flags.ready);
}

TEST(PlcProgram, EnableNeedsZeroSetpoints) {
  Harness h;
  h.command.control.enable = true;
  h.command.velocity_mps = {0.0, 0.1, 0.0};
  EXPECT_FALSE(h.run(100ms).status.flags.enabled);
  h.command.velocity_mps.setZero();
  EXPECT_TRUE(h.once().status.flags.enabled);
  // Once enabled, non-zero setpoints keep it enabled.
  h.command.velocity_mps = {0.0, 0.1, 0.0};
  EXPECT_TRUE(h.once().status.flags.enabled);
}

TEST(PlcProgram, GrantNeedsRequestAndExternalMode) {
  Harness h;
  h.command.control.enable = true;
  h.command.control.external_control_request = true;
  h.command.requested_mode = CraneMode::kLocal;
  auto out = h.once();
  EXPECT_TRUE(out.status.flags.enabled);
  EXPECT_FALSE(out.status.flags.external_control_granted);
  EXPECT_EQ(out.status.active_mode, CraneMode::kLocal);
  h.command.requested_mode = CraneMode::kExternalVelocity;
  out = h.once();
  EXPECT_TRUE(out.status.flags.external_control_granted);
  EXPECT_EQ(out.status.active_mode, CraneMode::kExternalVelocity);
  h.command.control.external_control_request = false;
  EXPECT_FALSE(h.once().status.flags.external_control_granted);
}

TEST(PlcProgram, RampsAtTheAccelerationLimitAndClampsSpeed) {
  Harness h;
  h.take_control();
  h.command.velocity_mps = {2.0, -2.0, 2.0};  // far above every max speed
  auto out = h.run(200ms);
  // 50 cycles of 4 ms at the axis' acceleration.
  EXPECT_NEAR(out.velocity_command_mps.x(), 0.5 * 0.2, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.y(), -0.5 * 0.2, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.z(), 0.3 * 0.2, 1e-9);
  out = h.run(2s);
  EXPECT_DOUBLE_EQ(out.velocity_command_mps.x(), 0.5);
  EXPECT_DOUBLE_EQ(out.velocity_command_mps.y(), -0.5);
  EXPECT_DOUBLE_EQ(out.velocity_command_mps.z(), 0.2);
  EXPECT_TRUE(out.status.flags.moving);
}

// With a deceleration ramp configured, a setpoint that slows an axis down ramps at it (a frequency converter's
// separate DEC ramp: a zero setpoint stops the crane sooner); speeding up stays at the acceleration limit.
TEST(PlcProgram, SlowsDownAtTheStopDecelerationAndSpeedsUpAtTheAccelerationLimit) {
  PlcProgramConfig c = config();
  c.stop_decel_mps2 = Eigen::Vector3d(1.0, 1.0, 0.6);
  Harness h({4.0, 2.5, 2.0}, 40.0, c);
  h.take_control();
  h.command.velocity_mps = {0.2, -0.2, 0.1};
  auto out = h.run(500ms);
  ASSERT_NEAR(out.velocity_command_mps.x(), 0.2, 1e-9);
  ASSERT_NEAR(out.velocity_command_mps.y(), -0.2, 1e-9);
  ASSERT_NEAR(out.velocity_command_mps.z(), 0.1, 1e-9);
  h.command.velocity_mps.setZero();
  out = h.run(100ms);  // 25 cycles of 4 ms
  EXPECT_NEAR(out.velocity_command_mps.x(), 0.2 - 1.0 * 0.1, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.y(), -0.2 + 1.0 * 0.1, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.z(), 0.1 - 0.6 * 0.1, 1e-9);
  out = h.run(120ms);
  EXPECT_TRUE(out.velocity_command_mps.isZero(0.0));
  h.command.velocity_mps = {-0.2, 0.2, -0.1};
  out = h.run(100ms);
  EXPECT_NEAR(out.velocity_command_mps.x(), -0.5 * 0.1, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.y(), 0.5 * 0.1, 1e-9);
  EXPECT_NEAR(out.velocity_command_mps.z(), -0.3 * 0.1, 1e-9);
}

TEST(PlcProgram, HeartbeatTimeoutStopsAndLatchesUntilReset) {
  Harness h;
  h.take_control();
  h.command.velocity_mps = {0.5, 0.0, 0.0};
  h.run(1500ms);
  ASSERT_DOUBLE_EQ(h.last.velocity_command_mps.x(), 0.5);

  h.heartbeat_alive = false;
  const auto stalled_at = h.program.time();
  std::chrono::nanoseconds fault_at{0};
  std::chrono::nanoseconds stopped_at{0};
  for (int i = 0; i < 200 && stopped_at == 0ns; ++i) {
    const auto out = h.once();
    if (out.status.flags.heartbeat_fault && fault_at == 0ns) fault_at = h.program.time();
    if (fault_at != 0ns && out.velocity_command_mps.isZero()) stopped_at = h.program.time();
  }
  ASSERT_NE(fault_at, 0ns);
  ASSERT_NE(stopped_at, 0ns);
  EXPECT_GT(fault_at - stalled_at, h.program.config().heartbeat_timeout);
  EXPECT_LE(fault_at - stalled_at, h.program.config().heartbeat_timeout + 4ms);
  // Quick stop from 0.5 m/s at 2 m/s^2: 250 ms.
  EXPECT_LE(stopped_at - fault_at, 250ms + 4ms);
  EXPECT_TRUE(h.last.status.flags.fault);
  EXPECT_FALSE(h.last.status.flags.enabled);
  EXPECT_FALSE(h.last.status.flags.ready);
  EXPECT_EQ(h.last.status.fault_code, FaultCode::kHeartbeatTimeout);

  // The heartbeat comes back: the fault stays latched and the setpoint stays without effect.
  h.heartbeat_alive = true;
  auto out = h.run(500ms);
  EXPECT_TRUE(out.status.flags.heartbeat_fault);
  EXPECT_TRUE(out.velocity_command_mps.isZero());

  // Reset with the old setpoint still in the registers: cleared, but not re-enabled.
  h.pulse_reset();
  EXPECT_FALSE(h.last.status.flags.fault);
  EXPECT_EQ(h.last.status.fault_code, FaultCode::kNone);
  EXPECT_FALSE(h.last.status.flags.enabled);
  EXPECT_TRUE(h.run(200ms).velocity_command_mps.isZero());
  h.take_control();
  h.command.velocity_mps = {0.2, 0.0, 0.0};
  EXPECT_GT(h.run(200ms).velocity_command_mps.x(), 0.0);
}

TEST(PlcProgram, WatchdogIdleWhileTheGatewayDoesNotHoldTheCrane) {
  Harness h;
  h.heartbeat_alive = false;
  const auto out = h.run(2s);
  EXPECT_FALSE(out.status.flags.fault);
  EXPECT_TRUE(out.status.flags.ready);
}

TEST(PlcProgram, WatchdogArmsWithEnableAndGivesAFullTimeout) {
  Harness h;
  h.heartbeat_alive = false;
  h.run(1s);
  h.command.control.enable = true;
  const auto timeout = h.program.config().heartbeat_timeout;
  EXPECT_FALSE(h.run(timeout - 8ms).status.flags.heartbeat_fault);
  EXPECT_TRUE(h.run(20ms).status.flags.heartbeat_fault);
}

TEST(PlcProgram, EmergencyStopLatchesUntilReleasedAndReset) {
  Harness h;
  h.take_control();
  h.command.velocity_mps = {0.0, 0.4, 0.0};
  h.run(1s);
  ASSERT_GT(h.last.velocity_command_mps.y(), 0.3);

  h.program.set_emergency_stop(true);
  auto out = h.once();
  EXPECT_TRUE(out.status.flags.emergency_stop);
  EXPECT_TRUE(out.status.flags.fault);
  EXPECT_EQ(out.status.fault_code, FaultCode::kEmergencyStop);
  out = h.run(300ms);
  EXPECT_TRUE(out.velocity_command_mps.isZero());

  // A reset while pressed does nothing.
  h.pulse_reset();
  EXPECT_TRUE(h.last.status.flags.emergency_stop);
  // Released: still latched, commands have no effect.
  h.program.set_emergency_stop(false);
  const double y = h.axes.read().position_m.y();
  out = h.run(500ms);
  EXPECT_TRUE(out.status.flags.emergency_stop);
  EXPECT_DOUBLE_EQ(h.axes.read().position_m.y(), y);
  // Released and reset: the crane needs zero setpoints to re-enable, then moves again.
  h.pulse_reset();
  EXPECT_FALSE(h.last.status.flags.fault);
  EXPECT_FALSE(h.last.status.flags.emergency_stop);
  h.take_control();
  h.command.velocity_mps = {0.0, 0.4, 0.0};
  h.run(200ms);
  EXPECT_GT(h.axes.read().position_m.y(), y);
}

TEST(PlcProgram, ResetIsEdgeTriggered) {
  Harness h;
  h.command.control.reset = true;  // held high
  h.once();
  h.program.set_emergency_stop(true);
  h.once();
  h.program.set_emergency_stop(false);
  EXPECT_TRUE(h.run(100ms).status.flags.emergency_stop);
  h.command.control.reset = false;
  h.once();
  h.command.control.reset = true;
  EXPECT_FALSE(h.once().status.flags.emergency_stop);
}

TEST(PlcProgram, SoftwareLimitsStopAtTheEndOfTheRange) {
  Harness h({7.0, 2.5, 3.5});
  h.take_control();
  h.command.velocity_mps = {0.5, 0.0, 0.2};
  double max_x = 0.0;
  double max_z = 0.0;
  for (int i = 0; i < 1500; ++i) {
    h.once();
    max_x = std::max(max_x, h.axes.read().position_m.x());
    max_z = std::max(max_z, h.axes.read().position_m.z());
  }
  const double tolerance = h.program.config().limit_switch_tolerance_m;
  EXPECT_LE(max_x, 8.0);
  EXPECT_LE(max_z, 4.0);
  EXPECT_NEAR(h.axes.read().position_m.x(), 8.0 - tolerance, 0.001);
  EXPECT_NEAR(h.axes.read().position_m.z(), 4.0 - tolerance, 0.001);
  EXPECT_TRUE(h.last.status.flags.limit_max[0]);
  EXPECT_TRUE(h.last.status.flags.limit_max[2]);
  EXPECT_FALSE(h.last.status.flags.limit_min[0]);
  EXPECT_FALSE(h.last.status.flags.limit_max[1]);
  EXPECT_TRUE(h.last.velocity_command_mps.isZero());
  EXPECT_FALSE(h.last.status.flags.fault);  // a limit switch is not a fault

  h.command.velocity_mps = {-0.5, 0.0, -0.2};  // away from the limit: allowed
  h.run(500ms);
  EXPECT_LT(h.axes.read().position_m.x(), 8.0 - tolerance - 0.01);
  EXPECT_FALSE(h.last.status.flags.limit_max[0]);
}

TEST(PlcProgram, LowerLimitTowardsMinimum) {
  Harness h({0.3, 0.3, 0.9});
  h.take_control();
  h.command.velocity_mps = {-0.5, -0.5, -0.2};
  h.run(3s);
  const auto p = h.axes.read().position_m;
  EXPECT_GE(p.x(), 0.0);
  EXPECT_GE(p.y(), 0.0);
  EXPECT_GE(p.z(), 0.7);
  EXPECT_TRUE(h.last.status.flags.limit_min[0]);
  EXPECT_TRUE(h.last.status.flags.limit_min[1]);
  EXPECT_TRUE(h.last.status.flags.limit_min[2]);
}

TEST(PlcProgram, OverloadBlocksHoistingButNotLowering) {
  Harness h({4.0, 2.5, 2.0}, 3200 * 1.2);
  h.take_control();
  h.command.velocity_mps = {0.0, 0.0, 0.2};
  auto out = h.run(500ms);
  EXPECT_TRUE(out.status.flags.overload);
  EXPECT_FALSE(out.status.flags.fault);
  EXPECT_EQ(out.status.fault_code, FaultCode::kOverload);
  EXPECT_DOUBLE_EQ(h.axes.read().position_m.z(), 2.0);
  h.command.velocity_mps = {0.1, 0.0, -0.2};
  h.run(500ms);
  EXPECT_LT(h.axes.read().position_m.z(), 2.0);
  EXPECT_GT(h.axes.read().position_m.x(), 4.0);
  // Not latched: the load is set down, hoisting works again.
  h.axes.set_load_kg(40);
  h.command.velocity_mps = {0.0, 0.0, 0.2};
  out = h.run(1500ms);
  EXPECT_FALSE(out.status.flags.overload);
  EXPECT_EQ(out.status.fault_code, FaultCode::kNone);
  EXPECT_GT(out.velocity_command_mps.z(), 0.0);
}

TEST(PlcProgram, InvalidCommandCountsAsEverythingOff) {
  Harness h;
  h.take_control();
  h.command.velocity_mps = {0.3, 0.0, 0.0};
  h.run(1s);
  h.command_valid = false;
  const auto out = h.run(1s);
  EXPECT_EQ(out.status.fault_code, FaultCode::kInvalidCommand);
  EXPECT_FALSE(out.status.flags.enabled);
  EXPECT_FALSE(out.status.flags.fault);
  EXPECT_TRUE(out.velocity_command_mps.isZero());
}

TEST(PlcProgram, StatusReportsTheMeasurement) {
  Harness h({1.0, 2.0, 3.0}, 123.0);
  const auto out = h.once();
  EXPECT_TRUE(out.status.position_m.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  EXPECT_DOUBLE_EQ(out.status.load_kg, 123.0);
  EXPECT_EQ(h.once().status.plc_heartbeat, out.status.plc_heartbeat + 1);
}

TEST(PlcProgramConfig, RejectsUnsafeOrUnusableSettings) {
  PlcProgramConfig c = config();
  c.heartbeat_timeout = 300ms;
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  c = config();
  c.quick_stop_decel_mps2.x() = 0.1;  // weaker than the normal ramp
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  c = config();
  c.stop_decel_mps2 = Eigen::Vector3d(0.4, 1.0, 0.6);  // bridge: slower than its acceleration
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  c.stop_decel_mps2 = Eigen::Vector3d(1.0, 1.0, 5.0);  // hoist: harder than its quick stop
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  c.stop_decel_mps2 = Eigen::Vector3d(1.0, 1.0, 0.6);
  EXPECT_NO_THROW(PlcProgram{c});
  c = config();
  c.limits.max_speed_mps.z() = 0.0;
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  c = config();
  c.overload_factor = 0.5;
  EXPECT_THROW(PlcProgram{c}, PlcConfigError);
  EXPECT_NO_THROW(PlcProgram{config()});
}

}  // namespace
}  // namespace rigger::plc
