#include "rigger/crane_protocol/register_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "rigger/crane_protocol/testing.hpp"

namespace rigger::crane {
namespace {

using ::rigger::crane::testing::reference_limits;

Plausibility test_plausibility() {
  Plausibility p;
  p.limits = reference_limits();
  return p;
}

CraneStatus plausible_status() {
  CraneStatus s;
  s.plc_heartbeat = 4711;
  s.flags.ready = true;
  s.flags.enabled = true;
  s.flags.external_control_granted = true;
  s.flags.moving = true;
  s.active_mode = CraneMode::kExternalVelocity;
  s.position_m = {3.25, 1.5, 2.125};
  s.velocity_mps = {-0.25, 0.1, -0.05};
  s.load_kg = 40;
  return s;
}

StatusRegisters status_registers(const CraneStatus& status) {
  return encode_status(status).registers;
}

std::size_t status_index(std::uint16_t address) { return address - reg::kStatusBlockStart; }

// --- primitives ----------------------------------------------------------------------------

TEST(Int16Register, SignEdgesRoundTrip) {
  const std::int16_t values[] = {std::numeric_limits<std::int16_t>::min(), -1, 0, 1,
                                 std::numeric_limits<std::int16_t>::max()};
  for (const std::int16_t v : values) {
    EXPECT_EQ(register_to_int16(int16_to_register(v)), v);
  }
  EXPECT_EQ(int16_to_register(-32768), 0x8000);
  EXPECT_EQ(int16_to_register(-1), 0xFFFF);
  EXPECT_EQ(int16_to_register(32767), 0x7FFF);
  EXPECT_EQ(register_to_int16(0x8000), -32768);
  EXPECT_EQ(register_to_int16(0x8001), -32767);
}

TEST(Int16Register, EveryRegisterValueRoundTrips) {
  for (std::uint32_t raw = 0; raw <= 0xFFFF; ++raw) {
    const auto value = static_cast<std::uint16_t>(raw);
    ASSERT_EQ(int16_to_register(register_to_int16(value)), value);
  }
}

TEST(Int32Split, HighWordFirst) {
  EXPECT_EQ(split_int32(0x12345678), (std::array<std::uint16_t, 2>{0x1234, 0x5678}));
  EXPECT_EQ(split_int32(65536), (std::array<std::uint16_t, 2>{1, 0}));
  EXPECT_EQ(split_int32(65535), (std::array<std::uint16_t, 2>{0, 0xFFFF}));
  EXPECT_EQ(split_int32(-1), (std::array<std::uint16_t, 2>{0xFFFF, 0xFFFF}));
  EXPECT_EQ(split_int32(-65536), (std::array<std::uint16_t, 2>{0xFFFF, 0}));
  EXPECT_EQ(split_int32(std::numeric_limits<std::int32_t>::min()),
            (std::array<std::uint16_t, 2>{0x8000, 0}));
}

TEST(Int32Split, EdgesRoundTrip) {
  const std::int32_t values[] = {std::numeric_limits<std::int32_t>::min(),
                                 std::numeric_limits<std::int32_t>::min() + 1,
                                 -65537,
                                 -65536,
                                 -32769,
                                 -32768,
                                 -1,
                                 0,
                                 1,
                                 32767,
                                 32768,
                                 65535,
                                 65536,
                                 std::numeric_limits<std::int32_t>::max()};
  for (const std::int32_t v : values) {
    const auto words = split_int32(v);
    EXPECT_EQ(join_int32(words[0], words[1]), v) << v;
  }
}

TEST(Saturate, Int16RoundsAndSaturates) {
  EXPECT_EQ(saturate_int16(32767.4).value, 32767);
  EXPECT_FALSE(saturate_int16(32767.4).saturated);
  EXPECT_EQ(saturate_int16(32767.6).value, 32767);
  EXPECT_TRUE(saturate_int16(32767.6).saturated);
  EXPECT_EQ(saturate_int16(-32768.4).value, -32768);
  EXPECT_FALSE(saturate_int16(-32768.4).saturated);
  EXPECT_EQ(saturate_int16(-32768.6).value, -32768);
  EXPECT_TRUE(saturate_int16(-32768.6).saturated);
  EXPECT_EQ(saturate_int16(-0.4).value, 0);
  EXPECT_EQ(saturate_int16(1.5).value, 2);
  EXPECT_EQ(saturate_int16(-1.5).value, -2);
  EXPECT_EQ(saturate_int16(1e300).value, 32767);
  EXPECT_EQ(saturate_int16(-std::numeric_limits<double>::infinity()).value, -32768);
  EXPECT_TRUE(saturate_int16(std::numeric_limits<double>::infinity()).saturated);
  EXPECT_EQ(saturate_int16(std::nan("")).value, 0);
  EXPECT_TRUE(saturate_int16(std::nan("")).saturated);
}

TEST(Saturate, Uint16AndInt32) {
  EXPECT_EQ(saturate_uint16(-0.4).value, 0);
  EXPECT_FALSE(saturate_uint16(-0.4).saturated);
  EXPECT_EQ(saturate_uint16(-1.0).value, 0);
  EXPECT_TRUE(saturate_uint16(-1.0).saturated);
  EXPECT_EQ(saturate_uint16(65535.0).value, 65535);
  EXPECT_TRUE(saturate_uint16(65536.0).saturated);
  EXPECT_EQ(saturate_int32(2147483647.0).value, std::numeric_limits<std::int32_t>::max());
  EXPECT_FALSE(saturate_int32(2147483647.0).saturated);
  EXPECT_TRUE(saturate_int32(2147483648.0).saturated);
  EXPECT_EQ(saturate_int32(-2147483648.0).value, std::numeric_limits<std::int32_t>::min());
  EXPECT_FALSE(saturate_int32(-2147483648.0).saturated);
  EXPECT_TRUE(saturate_int32(-2147483649.0).saturated);
}

// --- command block -------------------------------------------------------------------------

TEST(CommandBlock, RoundTripsEveryControlCombination) {
  for (unsigned bits = 0; bits < 8; ++bits) {
    CraneCommand command;
    command.control.enable = (bits & 1U) != 0;
    command.control.reset = (bits & 2U) != 0;
    command.control.external_control_request = (bits & 4U) != 0;
    command.requested_mode = bits % 2 == 0 ? CraneMode::kLocal : CraneMode::kExternalVelocity;
    command.velocity_mps = {0.123, -0.456, 0.2};
    command.gateway_heartbeat = static_cast<std::uint16_t>(65530 + bits);
    const auto encoded = encode_command(command);
    EXPECT_FALSE(encoded.saturated);
    const auto decoded = decode_command(encoded.registers);
    ASSERT_TRUE(decoded) << decoded.error.to_string();
    EXPECT_EQ(decoded.value->control, command.control);
    EXPECT_EQ(decoded.value->requested_mode, command.requested_mode);
    EXPECT_EQ(decoded.value->gateway_heartbeat, command.gateway_heartbeat);
    EXPECT_TRUE(decoded.value->velocity_mps.isApprox(command.velocity_mps, 1e-12));
  }
}

TEST(CommandBlock, VelocitySignEdgesAndSaturation) {
  CraneCommand command;
  command.velocity_mps = {-32.768, 32.767, -0.001};
  auto encoded = encode_command(command);
  EXPECT_FALSE(encoded.saturated);
  EXPECT_EQ(encoded.registers[reg::kSetpointVelocity + 0], 0x8000);
  EXPECT_EQ(encoded.registers[reg::kSetpointVelocity + 1], 0x7FFF);
  EXPECT_EQ(encoded.registers[reg::kSetpointVelocity + 2], 0xFFFF);
  auto decoded = decode_command(encoded.registers);
  ASSERT_TRUE(decoded);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.x(), -32.768);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.y(), 32.767);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.z(), -0.001);

  command.velocity_mps = {40.0, -40.0, std::nan("")};
  encoded = encode_command(command);
  EXPECT_TRUE(encoded.saturated);
  decoded = decode_command(encoded.registers);
  ASSERT_TRUE(decoded);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.x(), 32.767);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.y(), -32.768);
  EXPECT_DOUBLE_EQ(decoded.value->velocity_mps.z(), 0.0);
}

TEST(CommandBlock, RejectsUnknownControlBitsAndModes) {
  CommandRegisters registers{};
  registers[reg::kControlWord] = 0x0008;
  auto decoded = decode_command(registers);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kControlWord);
  EXPECT_NE(decoded.error.to_string().find("0x0008"), std::string::npos);

  registers[reg::kControlWord] = 0;
  registers[reg::kRequestedMode] = 2;
  decoded = decode_command(registers);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kRequestedMode);
  EXPECT_EQ(decoded.error.field, "requested mode");
}

// --- status block --------------------------------------------------------------------------

TEST(StatusWord, EveryKnownWordRoundTrips) {
  for (std::uint32_t word = 0; word <= status_bit::kKnownMask; ++word) {
    const auto w = static_cast<std::uint16_t>(word);
    ASSERT_EQ(encode_status_word(decode_status_word(w)), w);
  }
}

TEST(StatusWord, LimitBitsPerAxisAndDirection) {
  StatusFlags flags;
  flags.limit_max[2] = true;
  EXPECT_EQ(encode_status_word(flags), 1U << 13U);
  flags = {};
  flags.limit_min[0] = true;
  EXPECT_EQ(encode_status_word(flags), 1U << 8U);
}

TEST(StatusBlock, RoundTrip) {
  const CraneStatus status = plausible_status();
  const auto encoded = encode_status(status);
  EXPECT_FALSE(encoded.saturated);
  const auto decoded = decode_status(encoded.registers, test_plausibility());
  ASSERT_TRUE(decoded) << decoded.error.to_string();
  EXPECT_EQ(decoded.value->plc_heartbeat, status.plc_heartbeat);
  EXPECT_EQ(decoded.value->flags, status.flags);
  EXPECT_EQ(decoded.value->fault_code, status.fault_code);
  EXPECT_EQ(decoded.value->active_mode, status.active_mode);
  EXPECT_TRUE(decoded.value->position_m.isApprox(status.position_m, 1e-12));
  EXPECT_TRUE(decoded.value->velocity_mps.isApprox(status.velocity_mps, 1e-12));
  EXPECT_DOUBLE_EQ(decoded.value->load_kg, status.load_kg);
}

TEST(StatusBlock, RandomRoundTripsWithinResolution) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Plausibility plausibility = test_plausibility();
  const CraneLimits& l = plausibility.limits;
  for (int i = 0; i < 1000; ++i) {
    CraneStatus status = plausible_status();
    for (Eigen::Index a = 0; a < 3; ++a) {
      status.position_m[a] =
          l.position_min_m[a] + unit(rng) * (l.position_max_m[a] - l.position_min_m[a]);
      status.velocity_mps[a] = (2.0 * unit(rng) - 1.0) * l.max_speed_mps[a];
    }
    status.load_kg = unit(rng) * l.rated_load_kg;
    const auto decoded = decode_status(encode_status(status).registers, plausibility);
    ASSERT_TRUE(decoded) << decoded.error.to_string();
    EXPECT_LE((decoded.value->position_m - status.position_m).cwiseAbs().maxCoeff(), 0.0005);
    EXPECT_LE((decoded.value->velocity_mps - status.velocity_mps).cwiseAbs().maxCoeff(), 0.0005);
    EXPECT_LE(std::abs(decoded.value->load_kg - status.load_kg), 0.5);
  }
}

TEST(StatusBlock, NegativePositionsUseTwoWords) {
  Plausibility plausibility = test_plausibility();
  plausibility.limits.position_min_m.z() = -100.0;  // e.g. a pit below the floor
  CraneStatus status = plausible_status();
  status.position_m.z() = -0.001;
  const auto registers = status_registers(status);
  EXPECT_EQ(registers[status_index(reg::kPosition + 4)], 0xFFFF);
  EXPECT_EQ(registers[status_index(reg::kPosition + 5)], 0xFFFF);
  status.position_m.z() = -65.536;
  const auto far = status_registers(status);
  EXPECT_EQ(far[status_index(reg::kPosition + 4)], 0xFFFF);
  EXPECT_EQ(far[status_index(reg::kPosition + 5)], 0x0000);
  const auto decoded = decode_status(far, plausibility);
  ASSERT_TRUE(decoded) << decoded.error.to_string();
  EXPECT_DOUBLE_EQ(decoded.value->position_m.z(), -65.536);
}

TEST(StatusBlock, PositionSaturatesAtInt32) {
  CraneStatus status = plausible_status();
  status.position_m.x() = 3.0e6;  // 3e9 mm does not fit
  const auto encoded = encode_status(status);
  EXPECT_TRUE(encoded.saturated);
  const std::size_t i = status_index(reg::kPosition);
  EXPECT_EQ(join_int32(encoded.registers[i], encoded.registers[i + 1]),
            std::numeric_limits<std::int32_t>::max());
}

TEST(StatusBlock, RejectsUnknownStatusBits) {
  for (const std::uint16_t bit : {std::uint16_t{0x4000}, std::uint16_t{0x8000}}) {
    auto registers = status_registers(plausible_status());
    registers[status_index(reg::kStatusWord)] |= bit;
    const auto decoded = decode_status(registers, test_plausibility());
    ASSERT_FALSE(decoded);
    EXPECT_EQ(decoded.error.register_address, reg::kStatusWord);
    EXPECT_NE(decoded.error.reason.find("unknown bits"), std::string::npos);
  }
}

TEST(StatusBlock, RejectsUnknownFaultCodeAndMode) {
  auto registers = status_registers(plausible_status());
  registers[status_index(reg::kFaultCode)] = 99;
  auto decoded = decode_status(registers, test_plausibility());
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kFaultCode);

  registers = status_registers(plausible_status());
  registers[status_index(reg::kActiveMode)] = 0xFFFF;
  decoded = decode_status(registers, test_plausibility());
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kActiveMode);
}

TEST(StatusBlock, RejectsInconsistentFlags) {
  CraneStatus status = plausible_status();
  status.flags.enabled = false;  // granted without enabled
  EXPECT_FALSE(decode_status(status_registers(status), test_plausibility()));

  status = plausible_status();
  status.flags.heartbeat_fault = true;  // without the fault bit
  EXPECT_FALSE(decode_status(status_registers(status), test_plausibility()));

  status = plausible_status();
  status.flags.fault = true;  // with fault code 0
  auto decoded = decode_status(status_registers(status), test_plausibility());
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kFaultCode);

  status = plausible_status();
  status.flags.limit_min[1] = true;
  status.flags.limit_max[1] = true;
  decoded = decode_status(status_registers(status), test_plausibility());
  ASSERT_FALSE(decoded);
  EXPECT_NE(decoded.error.reason.find("trolley"), std::string::npos);

  status = plausible_status();
  status.active_mode = CraneMode::kLocal;  // granted in local mode
  EXPECT_FALSE(decode_status(status_registers(status), test_plausibility()));
}

TEST(StatusBlock, PositionRangeWithMargin) {
  const Plausibility plausibility = test_plausibility();
  CraneStatus status = plausible_status();
  status.position_m.y() = 5.0 + plausibility.position_margin_m;  // exactly at the edge
  EXPECT_TRUE(decode_status(status_registers(status), plausibility));
  status.position_m.y() += 0.001;
  auto decoded = decode_status(status_registers(status), plausibility);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kPosition + 2);
  EXPECT_EQ(decoded.error.field, "position trolley");

  status = plausible_status();
  status.position_m.z() = 0.7 - plausibility.position_margin_m - 0.001;
  decoded = decode_status(status_registers(status), plausibility);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kPosition + 4);
}

TEST(StatusBlock, RejectsVelocityAboveThePhysicalMaximum) {
  const Plausibility plausibility = test_plausibility();
  CraneStatus status = plausible_status();
  status.velocity_mps.z() = -0.2 * plausibility.speed_factor;  // at the edge: accepted
  EXPECT_TRUE(decode_status(status_registers(status), plausibility));

  auto registers = status_registers(plausible_status());
  registers[status_index(reg::kVelocity + 2)] = 0x8000;  // -32.768 m/s
  auto decoded = decode_status(registers, plausibility);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kVelocity + 2);
  EXPECT_NE(decoded.error.reason.find("-32768 mm/s"), std::string::npos);

  registers[status_index(reg::kVelocity + 2)] = 0;
  registers[status_index(reg::kVelocity)] = 0x7FFF;
  decoded = decode_status(registers, plausibility);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kVelocity);
}

TEST(StatusBlock, RejectsImplausibleLoad) {
  auto registers = status_registers(plausible_status());
  registers[status_index(reg::kLoadMass)] = 0xFFFF;
  const auto decoded = decode_status(registers, test_plausibility());
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kLoadMass);
  EXPECT_NE(decoded.error.to_string().find("65535 kg"), std::string::npos);
}

TEST(StatusBlock, LoadSaturatesAtZeroAndMaximum) {
  CraneStatus status = plausible_status();
  status.load_kg = -3.0;  // a noisy load cell
  auto encoded = encode_status(status);
  EXPECT_TRUE(encoded.saturated);
  EXPECT_EQ(encoded.registers[status_index(reg::kLoadMass)], 0);
  status.load_kg = 1e6;
  encoded = encode_status(status);
  EXPECT_EQ(encoded.registers[status_index(reg::kLoadMass)], 0xFFFF);
}

// --- limits block --------------------------------------------------------------------------

TEST(LimitsBlock, RoundTrip) {
  const CraneLimits limits = reference_limits();
  const auto encoded = encode_limits(limits);
  EXPECT_FALSE(encoded.saturated);
  EXPECT_EQ(encoded.registers[0], kMapVersion);
  const auto decoded = decode_limits(encoded.registers);
  ASSERT_TRUE(decoded) << decoded.error.to_string();
  EXPECT_FALSE(compare_limits(*decoded.value, limits).has_value());
  EXPECT_TRUE(decoded.value->position_min_m.isApprox(limits.position_min_m));
  EXPECT_TRUE(decoded.value->position_max_m.isApprox(limits.position_max_m));
  EXPECT_TRUE(decoded.value->max_speed_mps.isApprox(limits.max_speed_mps));
  EXPECT_TRUE(decoded.value->max_accel_mps2.isApprox(limits.max_accel_mps2));
  EXPECT_DOUBLE_EQ(decoded.value->rated_load_kg, limits.rated_load_kg);
}

TEST(LimitsBlock, RejectsOtherVersionsAndEmptyRanges) {
  auto registers = encode_limits(reference_limits()).registers;
  registers[0] = kMapVersion + 1;
  auto decoded = decode_limits(registers);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kMapVersion);

  CraneLimits limits = reference_limits();
  limits.position_max_m.x() = limits.position_min_m.x();
  decoded = decode_limits(encode_limits(limits).registers);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kPositionMax);

  limits = reference_limits();
  limits.max_speed_mps.y() = 0.0;
  decoded = decode_limits(encode_limits(limits).registers);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error.register_address, reg::kMaxSpeed + 1);
}

TEST(Limits, CheckAndCompare) {
  EXPECT_FALSE(check_limits(reference_limits()).has_value());
  CraneLimits bad = reference_limits();
  bad.max_accel_mps2.z() = std::nan("");
  ASSERT_TRUE(check_limits(bad).has_value());
  EXPECT_NE(check_limits(bad)->find("hoist"), std::string::npos);
  bad = reference_limits();
  bad.rated_load_kg = 70000;
  EXPECT_TRUE(check_limits(bad).has_value());

  CraneLimits other = reference_limits();
  other.position_max_m.x() += 0.01;
  ASSERT_TRUE(compare_limits(other, reference_limits()).has_value());
  EXPECT_NE(compare_limits(other, reference_limits())->find("bridge range"), std::string::npos);
  other = reference_limits();
  other.max_speed_mps.z() += 0.0004;  // below the register resolution
  EXPECT_FALSE(compare_limits(other, reference_limits()).has_value());
}

}  // namespace
}  // namespace rigger::crane
