#include "rigger/plc/plc_emulator.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>

#include "rigger/crane_protocol/modbus_context.hpp"
#include "rigger/crane_protocol/testing.hpp"
#include "rigger/plc/kinematic_crane_axes.hpp"

namespace rigger::plc {
namespace {

using namespace std::chrono_literals;
namespace reg = crane::reg;

PlcEmulatorConfig config() {
  PlcEmulatorConfig c;
  c.program.limits = crane::testing::reference_limits();
  c.server.port = 0;
  return c;
}

crane::Plausibility plausibility() {
  crane::Plausibility p;
  p.limits = config().program.limits;
  return p;
}

class PlcEmulatorTest : public ::testing::Test {
 protected:
  PlcEmulatorTest() : axes({2.0, 1.0, 3.0}, 40.0), plc(config(), axes) {
    plc.start_server();
    client = crane::make_tcp_client("127.0.0.1", plc.port(), 200ms);
    EXPECT_EQ(modbus_connect(client.get()), 0);
  }

  crane::CraneStatus read_status() {
    crane::StatusRegisters registers{};
    EXPECT_EQ(modbus_read_registers(client.get(), reg::kStatusBlockStart, reg::kStatusBlockCount,
                                    registers.data()),
              reg::kStatusBlockCount);
    const auto decoded = crane::decode_status(registers, plausibility());
    EXPECT_TRUE(decoded) << decoded.error.to_string();
    return decoded.value.value_or(crane::CraneStatus{});
  }

  void write(const crane::CraneCommand& command) {
    const auto registers = crane::encode_command(command).registers;
    ASSERT_EQ(modbus_write_registers(client.get(), reg::kCommandBlockStart, reg::kCommandBlockCount,
                                     registers.data()),
              reg::kCommandBlockCount);
  }

  KinematicCraneAxes axes;
  PlcEmulator plc;
  crane::ModbusContextPtr client;
};

TEST_F(PlcEmulatorTest, ServesTheLimitsBlock) {
  crane::LimitRegisters registers{};
  ASSERT_EQ(modbus_read_registers(client.get(), reg::kLimitsBlockStart, reg::kLimitsBlockCount,
                                  registers.data()),
            reg::kLimitsBlockCount);
  const auto limits = crane::decode_limits(registers);
  ASSERT_TRUE(limits) << limits.error.to_string();
  EXPECT_FALSE(crane::compare_limits(*limits.value, config().program.limits).has_value());
}

TEST_F(PlcEmulatorTest, StatusBlockRejectsWrites) {
  const std::uint16_t value = 1;
  EXPECT_EQ(modbus_write_register(client.get(), reg::kStatusWord, value), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_register(client.get(), reg::kMapVersion, value), -1);
}

TEST_F(PlcEmulatorTest, StepActsOnTheCommandBlockAndPublishesStatus) {
  plc.step(4ms);
  auto status = read_status();
  EXPECT_TRUE(status.flags.ready);
  EXPECT_FALSE(status.flags.enabled);
  EXPECT_DOUBLE_EQ(status.position_m.x(), 2.0);
  EXPECT_DOUBLE_EQ(status.load_kg, 40.0);

  crane::CraneCommand command;
  command.control.enable = true;
  command.control.external_control_request = true;
  command.requested_mode = crane::CraneMode::kExternalVelocity;
  write(command);
  plc.step(4ms);
  status = read_status();
  EXPECT_TRUE(status.flags.external_control_granted);

  command.velocity_mps = {0.1, 0.0, 0.0};
  for (int i = 0; i < 100; ++i) {
    ++command.gateway_heartbeat;
    write(command);
    plc.step(4ms);
    axes.advance(4ms);
  }
  status = read_status();
  EXPECT_GT(status.position_m.x(), 2.0);
  EXPECT_NEAR(status.velocity_mps.x(), 0.1, 0.001);
  const auto snapshot = plc.snapshot();
  EXPECT_EQ(snapshot.cycles, 103U);  // with the first scan at construction
  EXPECT_EQ(snapshot.command_registers[reg::kGatewayHeartbeat], 100);
  ASSERT_TRUE(snapshot.command.has_value());
  EXPECT_NEAR(snapshot.velocity_command_mps.x(), 0.1, 1e-9);
}

TEST_F(PlcEmulatorTest, InvalidCommandBlockIsReported) {
  const std::uint16_t garbage = 0x00F0;
  ASSERT_EQ(modbus_write_register(client.get(), reg::kControlWord, garbage), 1);
  plc.step(4ms);
  EXPECT_EQ(read_status().fault_code, crane::FaultCode::kInvalidCommand);
  EXPECT_FALSE(plc.snapshot().command.has_value());
}

TEST_F(PlcEmulatorTest, CycleThreadAndEmergencyStop) {
  plc.start_cycle_thread(4ms, [this](std::chrono::nanoseconds dt) { axes.advance(dt); });
  ASSERT_TRUE(plc.wait_until([](const PlcSnapshot& s) { return s.cycles >= 5; }, 2s));
  plc.set_emergency_stop(true);
  ASSERT_TRUE(
      plc.wait_until([](const PlcSnapshot& s) { return s.status.flags.emergency_stop; }, 2s));
  EXPECT_TRUE(read_status().flags.fault);
  plc.stop_cycle_thread();
  plc.stop_cycle_thread();
  const auto cycles = plc.snapshot().cycles;
  EXPECT_FALSE(plc.wait_until([&](const PlcSnapshot& s) { return s.cycles > cycles; }, 50ms));
}

TEST(PlcEmulatorConfig, RejectsABadProgramConfig) {
  KinematicCraneAxes axes;
  PlcEmulatorConfig c = config();
  c.program.heartbeat_timeout = 1s;
  EXPECT_THROW(PlcEmulator(c, axes), PlcConfigError);
}

}  // namespace
}  // namespace rigger::plc
