#include "rigger/crane_protocol/register_map.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace rigger::crane {
namespace {

constexpr double kMmPerM = 1000.0;

template <typename Int>
Saturated<Int> saturate(double value) {
  if (std::isnan(value)) {
    return {0, true};
  }
  const double rounded = std::round(value);
  constexpr auto kMin = static_cast<double>(std::numeric_limits<Int>::min());
  constexpr auto kMax = static_cast<double>(std::numeric_limits<Int>::max());
  if (rounded < kMin) {
    return {std::numeric_limits<Int>::min(), true};
  }
  if (rounded > kMax) {
    return {std::numeric_limits<Int>::max(), true};
  }
  return {static_cast<Int>(rounded), false};
}

std::string hex16(std::uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%04x", static_cast<unsigned>(value));
  return text;
}

std::string format_mm(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f mm", metres * kMmPerM);
  return text;
}

std::string axis_field(std::string_view what, std::size_t axis) {
  return std::string(what) + " " + std::string(axis_name(axis));
}

bool known_mode(std::uint16_t value) {
  return value == static_cast<std::uint16_t>(CraneMode::kLocal) ||
         value == static_cast<std::uint16_t>(CraneMode::kExternalVelocity);
}

bool known_fault_code(std::uint16_t value) {
  return value <= static_cast<std::uint16_t>(FaultCode::kOverload);
}

// Register offsets inside the blocks, so that the tables above stay the single source of truth.
constexpr std::size_t status_index(std::uint16_t address) {
  return static_cast<std::size_t>(address - reg::kStatusBlockStart);
}
constexpr std::size_t limits_index(std::uint16_t address) {
  return static_cast<std::size_t>(address - reg::kLimitsBlockStart);
}

template <std::size_t N>
void put_int32(std::array<std::uint16_t, N>& registers, std::size_t index, double metres,
               bool& saturated) {
  const auto mm = saturate_int32(metres * kMmPerM);
  saturated = saturated || mm.saturated;
  const auto words = split_int32(mm.value);
  registers[index] = words[0];
  registers[index + 1] = words[1];
}

template <std::size_t N>
double get_int32_m(const std::array<std::uint16_t, N>& registers, std::size_t index) {
  return static_cast<double>(join_int32(registers[index], registers[index + 1])) / kMmPerM;
}

}  // namespace

std::string_view axis_name(std::size_t axis) {
  switch (axis) {
    case 0:
      return "bridge";
    case 1:
      return "trolley";
    case 2:
      return "hoist";
    default:
      return "unknown";
  }
}

std::string_view fault_code_name(FaultCode code) {
  switch (code) {
    case FaultCode::kNone:
      return "none";
    case FaultCode::kEmergencyStop:
      return "emergency_stop";
    case FaultCode::kHeartbeatTimeout:
      return "heartbeat_timeout";
    case FaultCode::kInvalidCommand:
      return "invalid_command";
    case FaultCode::kOverload:
      return "overload";
  }
  return "unknown";
}

std::string_view mode_name(CraneMode mode) {
  switch (mode) {
    case CraneMode::kLocal:
      return "local";
    case CraneMode::kExternalVelocity:
      return "external_velocity";
  }
  return "unknown";
}

bool ControlFlags::operator==(const ControlFlags& other) const {
  return enable == other.enable && reset == other.reset &&
         external_control_request == other.external_control_request;
}

bool StatusFlags::operator==(const StatusFlags& other) const {
  return ready == other.ready && enabled == other.enabled &&
         external_control_granted == other.external_control_granted && moving == other.moving &&
         fault == other.fault && emergency_stop == other.emergency_stop &&
         overload == other.overload && heartbeat_fault == other.heartbeat_fault &&
         limit_min == other.limit_min && limit_max == other.limit_max;
}

std::string DecodeError::to_string() const {
  return "register " + std::to_string(register_address) + " (" + field + "): " + reason;
}

std::uint16_t int16_to_register(std::int16_t value) {
  return static_cast<std::uint16_t>(value);  // modulo 2^16: well defined
}

std::int16_t register_to_int16(std::uint16_t value) {
  // Written out because the narrowing conversion of values >= 2^15 is only
  // implementation-defined before C++20.
  const int wide = value >= 0x8000U ? static_cast<int>(value) - 0x10000 : static_cast<int>(value);
  return static_cast<std::int16_t>(wide);
}

std::array<std::uint16_t, 2> split_int32(std::int32_t value) {
  const auto bits = static_cast<std::uint32_t>(value);
  return {static_cast<std::uint16_t>(bits >> 16U), static_cast<std::uint16_t>(bits & 0xFFFFU)};
}

std::int32_t join_int32(std::uint16_t high, std::uint16_t low) {
  const std::uint32_t bits = (static_cast<std::uint32_t>(high) << 16U) | low;
  const std::int64_t wide = bits >= 0x80000000U ? static_cast<std::int64_t>(bits) - 0x100000000LL
                                                : static_cast<std::int64_t>(bits);
  return static_cast<std::int32_t>(wide);
}

Saturated<std::int16_t> saturate_int16(double value) { return saturate<std::int16_t>(value); }
Saturated<std::uint16_t> saturate_uint16(double value) { return saturate<std::uint16_t>(value); }
Saturated<std::int32_t> saturate_int32(double value) { return saturate<std::int32_t>(value); }

std::uint16_t encode_control_word(const ControlFlags& flags) {
  std::uint16_t word = 0;
  if (flags.enable) word |= control_bit::kEnable;
  if (flags.reset) word |= control_bit::kReset;
  if (flags.external_control_request) word |= control_bit::kExternalControlRequest;
  return word;
}

std::uint16_t encode_status_word(const StatusFlags& flags) {
  std::uint16_t word = 0;
  if (flags.ready) word |= status_bit::kReady;
  if (flags.enabled) word |= status_bit::kEnabled;
  if (flags.external_control_granted) word |= status_bit::kExternalControlGranted;
  if (flags.moving) word |= status_bit::kMoving;
  if (flags.fault) word |= status_bit::kFault;
  if (flags.emergency_stop) word |= status_bit::kEmergencyStop;
  if (flags.overload) word |= status_bit::kOverload;
  if (flags.heartbeat_fault) word |= status_bit::kHeartbeatFault;
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    if (flags.limit_min[axis]) word |= status_bit::limit_min(axis);
    if (flags.limit_max[axis]) word |= status_bit::limit_max(axis);
  }
  return word;
}

StatusFlags decode_status_word(std::uint16_t word) {
  StatusFlags flags;
  flags.ready = (word & status_bit::kReady) != 0;
  flags.enabled = (word & status_bit::kEnabled) != 0;
  flags.external_control_granted = (word & status_bit::kExternalControlGranted) != 0;
  flags.moving = (word & status_bit::kMoving) != 0;
  flags.fault = (word & status_bit::kFault) != 0;
  flags.emergency_stop = (word & status_bit::kEmergencyStop) != 0;
  flags.overload = (word & status_bit::kOverload) != 0;
  flags.heartbeat_fault = (word & status_bit::kHeartbeatFault) != 0;
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    flags.limit_min[axis] = (word & status_bit::limit_min(axis)) != 0;
    flags.limit_max[axis] = (word & status_bit::limit_max(axis)) != 0;
  }
  return flags;
}

Encoded<CommandRegisters> encode_command(const CraneCommand& command) {
  Encoded<CommandRegisters> out;
  out.registers[reg::kControlWord] = encode_control_word(command.control);
  out.registers[reg::kRequestedMode] = static_cast<std::uint16_t>(command.requested_mode);
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto mm_s =
        saturate_int16(command.velocity_mps[static_cast<Eigen::Index>(axis)] * kMmPerM);
    out.saturated = out.saturated || mm_s.saturated;
    out.registers[reg::kSetpointVelocity + axis] = int16_to_register(mm_s.value);
  }
  out.registers[reg::kGatewayHeartbeat] = command.gateway_heartbeat;
  return out;
}

Decoded<CraneCommand> decode_command(const CommandRegisters& registers) {
  const std::uint16_t word = registers[reg::kControlWord];
  if ((word & ~control_bit::kKnownMask) != 0) {
    return Decoded<CraneCommand>::failure(
        reg::kControlWord, "control word",
        "unknown bits " + hex16(static_cast<std::uint16_t>(word & ~control_bit::kKnownMask)));
  }
  const std::uint16_t mode = registers[reg::kRequestedMode];
  if (!known_mode(mode)) {
    return Decoded<CraneCommand>::failure(
        reg::kRequestedMode, "requested mode",
        "unknown mode " + std::to_string(mode) + " (expected 0 local or 1 external velocity)");
  }
  CraneCommand command;
  command.control.enable = (word & control_bit::kEnable) != 0;
  command.control.reset = (word & control_bit::kReset) != 0;
  command.control.external_control_request = (word & control_bit::kExternalControlRequest) != 0;
  command.requested_mode = static_cast<CraneMode>(mode);
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    command.velocity_mps[static_cast<Eigen::Index>(axis)] =
        register_to_int16(registers[reg::kSetpointVelocity + axis]) / kMmPerM;
  }
  command.gateway_heartbeat = registers[reg::kGatewayHeartbeat];
  return Decoded<CraneCommand>::success(command);
}

Encoded<StatusRegisters> encode_status(const CraneStatus& status) {
  Encoded<StatusRegisters> out;
  auto& r = out.registers;
  r[status_index(reg::kPlcHeartbeat)] = status.plc_heartbeat;
  r[status_index(reg::kStatusWord)] = encode_status_word(status.flags);
  r[status_index(reg::kFaultCode)] = static_cast<std::uint16_t>(status.fault_code);
  r[status_index(reg::kActiveMode)] = static_cast<std::uint16_t>(status.active_mode);
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    put_int32(r, status_index(reg::kPosition) + 2 * axis, status.position_m[i], out.saturated);
    const auto mm_s = saturate_int16(status.velocity_mps[i] * kMmPerM);
    out.saturated = out.saturated || mm_s.saturated;
    r[status_index(reg::kVelocity) + axis] = int16_to_register(mm_s.value);
  }
  const auto load = saturate_uint16(status.load_kg);
  out.saturated = out.saturated || load.saturated;
  r[status_index(reg::kLoadMass)] = load.value;
  return out;
}

Decoded<CraneStatus> decode_status(const StatusRegisters& registers,
                                   const Plausibility& plausibility) {
  using Result = Decoded<CraneStatus>;
  const auto& r = registers;
  const std::uint16_t word = r[status_index(reg::kStatusWord)];
  if ((word & ~status_bit::kKnownMask) != 0) {
    return Result::failure(
        reg::kStatusWord, "status word",
        "unknown bits " + hex16(static_cast<std::uint16_t>(word & ~status_bit::kKnownMask)));
  }
  const std::uint16_t fault = r[status_index(reg::kFaultCode)];
  if (!known_fault_code(fault)) {
    return Result::failure(reg::kFaultCode, "fault code",
                           "unknown fault code " + std::to_string(fault));
  }
  const std::uint16_t mode = r[status_index(reg::kActiveMode)];
  if (!known_mode(mode)) {
    return Result::failure(
        reg::kActiveMode, "active mode",
        "unknown mode " + std::to_string(mode) + " (expected 0 local or 1 external velocity)");
  }

  CraneStatus status;
  status.plc_heartbeat = r[status_index(reg::kPlcHeartbeat)];
  status.flags = decode_status_word(word);
  status.fault_code = static_cast<FaultCode>(fault);
  status.active_mode = static_cast<CraneMode>(mode);

  // Flag combinations the PLC program can never produce.
  const auto& f = status.flags;
  if (f.external_control_granted && !f.enabled) {
    return Result::failure(reg::kStatusWord, "status word",
                           "external control granted while not enabled");
  }
  if (f.external_control_granted && status.active_mode != CraneMode::kExternalVelocity) {
    return Result::failure(
        reg::kActiveMode, "active mode",
        "external control granted in mode " + std::string(mode_name(status.active_mode)));
  }
  if ((f.heartbeat_fault || f.emergency_stop) && !f.fault) {
    return Result::failure(reg::kStatusWord, "status word",
                           "e-stop or heartbeat fault without the fault bit");
  }
  if (f.fault && status.fault_code == FaultCode::kNone) {
    return Result::failure(reg::kFaultCode, "fault code", "fault bit set but fault code is 0");
  }
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    if (f.limit_min[axis] && f.limit_max[axis]) {
      return Result::failure(
          reg::kStatusWord, "status word",
          "both limit switches of the " + std::string(axis_name(axis)) + " active");
    }
  }

  const CraneLimits& limits = plausibility.limits;
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const std::size_t pos_index = status_index(reg::kPosition) + 2 * axis;
    status.position_m[i] = get_int32_m(r, pos_index);
    const double low = limits.position_min_m[i] - plausibility.position_margin_m;
    const double high = limits.position_max_m[i] + plausibility.position_margin_m;
    if (status.position_m[i] < low || status.position_m[i] > high) {
      return Result::failure(static_cast<std::uint16_t>(reg::kPosition + 2 * axis),
                             axis_field("position", axis),
                             format_mm(status.position_m[i]) + " outside the plausible range [" +
                                 format_mm(low) + ", " + format_mm(high) + "]");
    }
    const std::uint16_t vel_address = static_cast<std::uint16_t>(reg::kVelocity + axis);
    status.velocity_mps[i] = register_to_int16(r[status_index(vel_address)]) / kMmPerM;
    const double max_speed = limits.max_speed_mps[i] * plausibility.speed_factor;
    if (std::abs(status.velocity_mps[i]) > max_speed) {
      return Result::failure(vel_address, axis_field("velocity", axis),
                             format_mm(status.velocity_mps[i]) + "/s above the physical maximum " +
                                 format_mm(max_speed) + "/s");
    }
  }
  status.load_kg = r[status_index(reg::kLoadMass)];
  const double max_load = limits.rated_load_kg * plausibility.load_factor;
  if (status.load_kg > max_load) {
    return Result::failure(reg::kLoadMass, "load mass",
                           std::to_string(r[status_index(reg::kLoadMass)]) +
                               " kg above the plausible maximum " +
                               std::to_string(static_cast<long>(max_load)) + " kg");
  }
  return Result::success(status);
}

Encoded<LimitRegisters> encode_limits(const CraneLimits& limits) {
  Encoded<LimitRegisters> out;
  auto& r = out.registers;
  r[limits_index(reg::kMapVersion)] = kMapVersion;
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const auto speed = saturate_uint16(limits.max_speed_mps[i] * kMmPerM);
    const auto accel = saturate_uint16(limits.max_accel_mps2[i] * kMmPerM);
    out.saturated = out.saturated || speed.saturated || accel.saturated;
    r[limits_index(reg::kMaxSpeed) + axis] = speed.value;
    r[limits_index(reg::kMaxAcceleration) + axis] = accel.value;
    put_int32(r, limits_index(reg::kPositionMin) + 2 * axis, limits.position_min_m[i],
              out.saturated);
    put_int32(r, limits_index(reg::kPositionMax) + 2 * axis, limits.position_max_m[i],
              out.saturated);
  }
  const auto rated = saturate_uint16(limits.rated_load_kg);
  out.saturated = out.saturated || rated.saturated;
  r[limits_index(reg::kRatedLoad)] = rated.value;
  return out;
}

Decoded<CraneLimits> decode_limits(const LimitRegisters& registers) {
  using Result = Decoded<CraneLimits>;
  const auto& r = registers;
  const std::uint16_t version = r[limits_index(reg::kMapVersion)];
  if (version != kMapVersion) {
    return Result::failure(
        reg::kMapVersion, "map version",
        "version " + std::to_string(version) + ", expected " + std::to_string(kMapVersion));
  }
  CraneLimits limits;
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const auto speed_address = static_cast<std::uint16_t>(reg::kMaxSpeed + axis);
    const auto accel_address = static_cast<std::uint16_t>(reg::kMaxAcceleration + axis);
    limits.max_speed_mps[i] = r[limits_index(speed_address)] / kMmPerM;
    limits.max_accel_mps2[i] = r[limits_index(accel_address)] / kMmPerM;
    limits.position_min_m[i] = get_int32_m(r, limits_index(reg::kPositionMin) + 2 * axis);
    limits.position_max_m[i] = get_int32_m(r, limits_index(reg::kPositionMax) + 2 * axis);
    if (limits.max_speed_mps[i] <= 0.0) {
      return Result::failure(speed_address, axis_field("max speed", axis), "must be positive");
    }
    if (limits.max_accel_mps2[i] <= 0.0) {
      return Result::failure(accel_address, axis_field("max acceleration", axis),
                             "must be positive");
    }
    if (limits.position_min_m[i] >= limits.position_max_m[i]) {
      return Result::failure(static_cast<std::uint16_t>(reg::kPositionMax + 2 * axis),
                             axis_field("position max", axis),
                             format_mm(limits.position_max_m[i]) + " not above the minimum " +
                                 format_mm(limits.position_min_m[i]));
    }
  }
  limits.rated_load_kg = r[limits_index(reg::kRatedLoad)];
  if (limits.rated_load_kg <= 0.0) {
    return Result::failure(reg::kRatedLoad, "rated load", "must be positive");
  }
  return Result::success(limits);
}

std::optional<std::string> check_limits(const CraneLimits& limits) {
  constexpr double kMaxRegisterValue = 65.535;  // uint16 in thousandths
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const std::string name(axis_name(axis));
    if (!std::isfinite(limits.position_min_m[i]) || !std::isfinite(limits.position_max_m[i]) ||
        std::abs(limits.position_min_m[i]) > 2.0e6 || std::abs(limits.position_max_m[i]) > 2.0e6) {
      return name + " range: must be finite and within +-2000 km";
    }
    if (!(limits.position_min_m[i] < limits.position_max_m[i])) {
      return name + " range: minimum must be below maximum";
    }
    if (!(limits.max_speed_mps[i] >= 0.001 && limits.max_speed_mps[i] <= kMaxRegisterValue)) {
      return name + " max speed: must be in [0.001, 65.535] m/s";
    }
    if (!(limits.max_accel_mps2[i] >= 0.001 && limits.max_accel_mps2[i] <= kMaxRegisterValue)) {
      return name + " max acceleration: must be in [0.001, 65.535] m/s^2";
    }
  }
  if (!(limits.rated_load_kg >= 1.0 && limits.rated_load_kg <= 65535.0)) {
    return std::string("rated load: must be in [1, 65535] kg");
  }
  return std::nullopt;
}

std::optional<std::string> compare_limits(const CraneLimits& plc, const CraneLimits& configured) {
  // Half a register step plus rounding slack: the PLC's values went through the registers.
  constexpr double kTolerance = 0.0006;
  const auto differs = [](double a, double b, double tolerance) {
    return !(std::abs(a - b) <= tolerance);
  };
  for (std::size_t axis = 0; axis < kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const std::string name(axis_name(axis));
    if (differs(plc.position_min_m[i], configured.position_min_m[i], kTolerance) ||
        differs(plc.position_max_m[i], configured.position_max_m[i], kTolerance)) {
      return name + " range: PLC [" + format_mm(plc.position_min_m[i]) + ", " +
             format_mm(plc.position_max_m[i]) + "], configured [" +
             format_mm(configured.position_min_m[i]) + ", " +
             format_mm(configured.position_max_m[i]) + "]";
    }
    if (differs(plc.max_speed_mps[i], configured.max_speed_mps[i], kTolerance)) {
      return name + " max speed: PLC " + format_mm(plc.max_speed_mps[i]) + "/s, configured " +
             format_mm(configured.max_speed_mps[i]) + "/s";
    }
    if (differs(plc.max_accel_mps2[i], configured.max_accel_mps2[i], kTolerance)) {
      return name + " max acceleration: PLC " + format_mm(plc.max_accel_mps2[i]) +
             "/s^2, configured " + format_mm(configured.max_accel_mps2[i]) + "/s^2";
    }
  }
  if (differs(plc.rated_load_kg, configured.rated_load_kg, 0.6)) {
    return "rated load: PLC " + std::to_string(static_cast<long>(plc.rated_load_kg)) +
           " kg, configured " + std::to_string(static_cast<long>(configured.rated_load_kg)) + " kg";
  }
  return std::nullopt;
}

}  // namespace rigger::crane
