#include "gateway_logic.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "rigger/crane_protocol/testing.hpp"

namespace rigger::crane_gateway {
namespace {

using ::rigger::crane::testing::reference_limits;

using namespace std::chrono_literals;
namespace reg = crane::reg;

const WallTime kWall0 = WallTime(std::chrono::seconds(1'700'000'000));
const SteadyTime kSteady0 = SteadyTime(std::chrono::seconds(1000));

GatewayLogicConfig config() {
  GatewayLogicConfig c;
  c.plausibility.limits = reference_limits();
  return c;
}

crane::CraneStatus granted_status(std::uint16_t plc_heartbeat) {
  crane::CraneStatus s;
  s.plc_heartbeat = plc_heartbeat;
  s.flags.ready = true;
  s.flags.enabled = true;
  s.flags.external_control_granted = true;
  s.active_mode = crane::CraneMode::kExternalVelocity;
  s.position_m = {4.0, 2.5, 2.0};
  s.load_kg = 40;
  return s;
}

crane::StatusRegisters registers(const crane::CraneStatus& status) {
  return crane::encode_status(status).registers;
}

crane::CraneCommand decode(const crane::CommandRegisters& registers) {
  const auto decoded = crane::decode_command(registers);
  EXPECT_TRUE(decoded) << decoded.error.to_string();
  return decoded.value.value_or(crane::CraneCommand{});
}

VelocityCommand velocity(double vx, WallTime stamp, std::uint64_t seq) {
  VelocityCommand c;
  c.velocity_mps = {vx, 0.0, 0.0};
  c.stamp = stamp;
  c.seq = seq;
  return c;
}

// A logic connected at (kWall0, kSteady0) with a PLC that grants external control.
class Connected : public ::testing::Test {
 protected:
  Connected() : logic(config()) {
    const auto mismatch =
        logic.on_connected(crane::encode_limits(reference_limits()).registers, kWall0, kSteady0);
    EXPECT_FALSE(mismatch.has_value()) << mismatch.value_or("");
    logic.set_control({true, true});
  }

  /// One cycle at kSteady0 + t / kWall0 + t with a granted status.
  crane::CraneCommand cycle(std::chrono::nanoseconds t, bool granted = true) {
    crane::CraneStatus status = granted_status(++plc_heartbeat);
    if (!granted) {
      status.flags.external_control_granted = false;
      status.active_mode = crane::CraneMode::kLocal;
    }
    logic.on_status(registers(status), kSteady0 + t);
    return decode(logic.next_command(kWall0 + t));
  }

  GatewayLogic logic;
  std::uint16_t plc_heartbeat = 0;
};

TEST(GatewayLogic, StartsDisconnectedWithZeroSetpoints) {
  GatewayLogic logic(config());
  EXPECT_FALSE(logic.state().link_up);
  EXPECT_EQ(logic.state().fault, GatewayFault::kLinkDown);
  const auto command = decode(logic.next_command(kWall0));
  EXPECT_TRUE(command.velocity_mps.isZero());
}

TEST(GatewayLogic, RefusesAPlcWithOtherLimitsOrMap) {
  GatewayLogic logic(config());
  crane::CraneLimits other = reference_limits();
  other.max_speed_mps.x() = 1.0;
  auto mismatch = logic.on_connected(crane::encode_limits(other).registers, kWall0, kSteady0);
  ASSERT_TRUE(mismatch.has_value());
  EXPECT_NE(mismatch->find("bridge max speed"), std::string::npos);
  EXPECT_EQ(logic.state().fault, GatewayFault::kPlcMapMismatch);
  EXPECT_FALSE(logic.state().link_up);

  auto wrong_version = crane::encode_limits(reference_limits()).registers;
  wrong_version[0] = 99;
  mismatch = logic.on_connected(wrong_version, kWall0, kSteady0);
  ASSERT_TRUE(mismatch.has_value());
  EXPECT_NE(mismatch->find("register 32"), std::string::npos);
}

TEST_F(Connected, WritesFreshCommandsWhileGranted) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 5ms, 1), kWall0 + 5ms), CommandVerdict::kAccepted);
  const auto command = cycle(10ms);
  EXPECT_DOUBLE_EQ(command.velocity_mps.x(), 0.3);
  EXPECT_TRUE(command.control.enable);
  EXPECT_TRUE(command.control.external_control_request);
  EXPECT_EQ(command.requested_mode, crane::CraneMode::kExternalVelocity);
  EXPECT_FALSE(command.control.reset);
  EXPECT_TRUE(logic.state().external_control_granted);
  EXPECT_EQ(logic.state().fault, GatewayFault::kNone);
}

TEST_F(Connected, ZeroWithoutTheGrant) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 5ms, 1), kWall0 + 5ms), CommandVerdict::kAccepted);
  EXPECT_TRUE(cycle(10ms, false).velocity_mps.isZero());
  EXPECT_FALSE(logic.state().external_control_granted);
  EXPECT_DOUBLE_EQ(cycle(20ms, true).velocity_mps.x(), 0.3);
}

TEST_F(Connected, ZeroAsSoonAsWeWithdrawTheRequest) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 5ms, 1), kWall0 + 5ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(10ms).velocity_mps.x(), 0.3);
  logic.set_control({true, false});
  // The PLC still reports the grant (it has not seen the withdrawal yet): zero anyway.
  const auto command = cycle(20ms, true);
  EXPECT_TRUE(command.velocity_mps.isZero());
  EXPECT_FALSE(command.control.external_control_request);
}

TEST_F(Connected, ZeroOnceTheCommandIsOlderThanItsTimeout) {
  const auto timeout = config().command_timeout;
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 5ms, 1), kWall0 + 5ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(5ms + timeout).velocity_mps.x(), 0.3);
  EXPECT_TRUE(cycle(5ms + timeout + 1ns).velocity_mps.isZero());
}

TEST_F(Connected, ASafeStopZeroesAtOnceAndRefusesCommandsUntilItsReset) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 5ms, 1), kWall0 + 5ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(10ms).velocity_mps.x(), 0.3);
  logic.set_safe_stop(true, "riggerctl: estop", kWall0 + 12ms);
  // The command is still fresh, but the next block carries zero.
  EXPECT_TRUE(cycle(15ms).velocity_mps.isZero());
  EXPECT_TRUE(logic.state().safe_stop);
  EXPECT_EQ(logic.state().safe_stop_reason, "riggerctl: estop");
  EXPECT_EQ(logic.submit(velocity(0.3, kWall0 + 20ms, 2), kWall0 + 20ms), CommandVerdict::kSafeStop);
  EXPECT_TRUE(cycle(25ms).velocity_mps.isZero());
  // After the reset, a command stamped before it is not replayed; a fresh one moves the crane.
  logic.set_safe_stop(false, "", kWall0 + 30ms);
  EXPECT_FALSE(logic.state().safe_stop);
  EXPECT_EQ(logic.submit(velocity(0.3, kWall0 + 28ms, 3), kWall0 + 31ms), CommandVerdict::kBeforeReconnect);
  ASSERT_EQ(logic.submit(velocity(0.2, kWall0 + 32ms, 4), kWall0 + 32ms), CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(35ms).velocity_mps.x(), 0.2);
}

TEST_F(Connected, ClampsToTheMaxSpeed) {
  VelocityCommand fast = velocity(3.0, kWall0 + 1ms, 1);
  fast.velocity_mps.z() = -3.0;
  ASSERT_EQ(logic.submit(fast, kWall0 + 1ms), CommandVerdict::kAccepted);
  const auto command = cycle(2ms);
  EXPECT_DOUBLE_EQ(command.velocity_mps.x(), 0.5);
  EXPECT_DOUBLE_EQ(command.velocity_mps.z(), -0.2);
  EXPECT_EQ(logic.state().clamped_setpoints, 1U);
}

TEST_F(Connected, HeartbeatChangesEveryCycleAndWraps) {
  std::uint16_t previous = cycle(1ms).gateway_heartbeat;
  for (int i = 2; i < 70000; ++i) {
    const std::uint16_t heartbeat =
        decode(logic.next_command(kWall0 + std::chrono::milliseconds(i))).gateway_heartbeat;
    ASSERT_EQ(heartbeat, static_cast<std::uint16_t>(previous + 1));
    previous = heartbeat;
  }
}

TEST_F(Connected, NeverReplaysACommandAfterAReconnect) {
  // The command is young enough by age alone, but predates the reconnect.
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 10ms, 1), kWall0 + 10ms),
            CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(20ms).velocity_mps.x(), 0.3);

  logic.on_link_lost("read status block: Connection reset by peer", kSteady0 + 30ms);
  EXPECT_FALSE(logic.state().link_up);
  EXPECT_EQ(logic.state().fault, GatewayFault::kLinkDown);
  EXPECT_TRUE(logic.state().setpoint_mps.isZero());
  EXPECT_EQ(logic.state().link_losses, 1U);
  // Sent while the link was down.
  ASSERT_EQ(logic.submit(velocity(0.4, kWall0 + 40ms, 2), kWall0 + 40ms),
            CommandVerdict::kAccepted);

  ASSERT_FALSE(logic.on_connected(crane::encode_limits(reference_limits()).registers, kWall0 + 50ms,
                                  kSteady0 + 50ms));
  EXPECT_TRUE(cycle(60ms).velocity_mps.isZero());
  EXPECT_EQ(logic.submit(velocity(0.4, kWall0 + 45ms, 3), kWall0 + 60ms),
            CommandVerdict::kBeforeReconnect);
  EXPECT_TRUE(cycle(70ms).velocity_mps.isZero());
  ASSERT_EQ(logic.submit(velocity(0.1, kWall0 + 71ms, 4), kWall0 + 71ms),
            CommandVerdict::kAccepted);
  EXPECT_DOUBLE_EQ(cycle(80ms).velocity_mps.x(), 0.1);
  EXPECT_EQ(logic.state().connects, 2U);
}

TEST_F(Connected, ImplausibleStatusRevokesTheGrant) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 1ms, 1), kWall0 + 1ms), CommandVerdict::kAccepted);
  ASSERT_DOUBLE_EQ(cycle(1ms).velocity_mps.x(), 0.3);
  crane::CraneStatus status = granted_status(++plc_heartbeat);
  status.position_m.y() = 9.0;  // 4 m beyond the trolley's range
  EXPECT_EQ(logic.on_status(registers(status), kSteady0 + 2ms), GatewayFault::kImplausibleState);
  EXPECT_NE(logic.state().fault_reason.find("register 22 (position trolley)"), std::string::npos);
  EXPECT_TRUE(decode(logic.next_command(kWall0 + 2ms)).velocity_mps.isZero());
  EXPECT_EQ(logic.state().implausible_states, 1U);
  ASSERT_TRUE(logic.state().plc.has_value());
  EXPECT_DOUBLE_EQ(logic.state().plc->position_m.y(), 2.5);  // the last plausible one stays

  auto bad_bits = registers(granted_status(++plc_heartbeat));
  bad_bits[reg::kStatusWord - reg::kStatusBlockStart] |= 0x8000;
  EXPECT_EQ(logic.on_status(bad_bits, kSteady0 + 3ms), GatewayFault::kImplausibleState);
  EXPECT_NE(logic.state().fault_reason.find("unknown bits 0x8000"), std::string::npos);

  EXPECT_DOUBLE_EQ(cycle(4ms).velocity_mps.x(), 0.3);  // plausible again
  EXPECT_EQ(logic.state().fault, GatewayFault::kNone);
}

TEST_F(Connected, StalledPlcHeartbeatMeansZero) {
  ASSERT_EQ(logic.submit(velocity(0.3, kWall0 + 1ms, 1), kWall0 + 1ms), CommandVerdict::kAccepted);
  const auto status = registers(granted_status(7));
  const auto timeout = config().plc_heartbeat_timeout;
  EXPECT_EQ(logic.on_status(status, kSteady0), GatewayFault::kNone);
  EXPECT_EQ(logic.on_status(status, kSteady0 + timeout), GatewayFault::kNone);
  EXPECT_EQ(logic.on_status(status, kSteady0 + timeout + 1ms), GatewayFault::kPlcHeartbeatStalled);
  EXPECT_TRUE(decode(logic.next_command(kWall0 + 10ms)).velocity_mps.isZero());
  EXPECT_EQ(logic.on_status(registers(granted_status(8)), kSteady0 + timeout + 2ms),
            GatewayFault::kNone);
}

TEST_F(Connected, ReportsThePlcFault) {
  crane::CraneStatus status = granted_status(++plc_heartbeat);
  status.flags = {};
  status.flags.fault = true;
  status.flags.heartbeat_fault = true;
  status.active_mode = crane::CraneMode::kLocal;
  status.fault_code = crane::FaultCode::kHeartbeatTimeout;
  EXPECT_EQ(logic.on_status(registers(status), kSteady0 + 1ms), GatewayFault::kPlcFault);
  EXPECT_EQ(logic.state().fault_reason, "PLC fault heartbeat_timeout");
  EXPECT_FALSE(logic.state().external_control_granted);
}

TEST_F(Connected, ResetIsAPulseOfConfiguredLength) {
  logic.request_reset();
  for (int i = 0; i < config().reset_pulse_cycles; ++i) {
    EXPECT_TRUE(cycle(std::chrono::milliseconds(i + 1)).control.reset);
  }
  EXPECT_FALSE(cycle(10ms).control.reset);
  EXPECT_FALSE(cycle(11ms).control.reset);
}

TEST_F(Connected, ControlRequestMapsToControlWordAndMode) {
  logic.set_control({true, false});
  auto command = cycle(1ms, false);
  EXPECT_TRUE(command.control.enable);
  EXPECT_FALSE(command.control.external_control_request);
  EXPECT_EQ(command.requested_mode, crane::CraneMode::kLocal);
  logic.set_control({});
  command = cycle(2ms, false);
  EXPECT_FALSE(command.control.enable);
}

TEST(GatewayLogic, RejectsBadConfiguration) {
  GatewayLogicConfig c = config();
  c.reset_pulse_cycles = 0;
  EXPECT_THROW(GatewayLogic{c}, std::invalid_argument);
  c = config();
  c.command_timeout = 0ms;
  EXPECT_THROW(GatewayLogic{c}, std::invalid_argument);
  c = config();
  c.plausibility.limits.rated_load_kg = 0;
  EXPECT_THROW(GatewayLogic{c}, std::invalid_argument);
  EXPECT_EQ(fault_name(GatewayFault::kPlcHeartbeatStalled), "plc_heartbeat_stalled");
}

}  // namespace
}  // namespace rigger::crane_gateway
