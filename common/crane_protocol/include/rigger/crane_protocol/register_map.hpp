#pragma once
// The crane PLC's Modbus TCP register map (docs/crane-modbus.md) and its encoding.
//
// Everything here is pure: register arrays in, domain values (SI units) out, and back. The
// gateway (client) and the PLC emulator (server) share these functions so that the two ends of
// the wire cannot disagree.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace rigger::crane {

/// Crane axes in the crane frame: bridge along x, trolley along y, hoist along z (hook height,
/// up positive). Index into the per-axis arrays and Eigen vectors.
enum class Axis : std::size_t { kBridge = 0, kTrolley = 1, kHoist = 2 };
inline constexpr std::size_t kAxisCount = 3;

/// "bridge", "trolley" or "hoist".
std::string_view axis_name(std::size_t axis);

/// Holding register addresses (0-based protocol addresses; reference number = 40001 + address).
namespace reg {
// Command block: written by the gateway, read by the PLC. Addresses 0..15 are writable.
inline constexpr std::uint16_t kControlWord = 0;
inline constexpr std::uint16_t kRequestedMode = 1;
inline constexpr std::uint16_t kSetpointVelocity = 2;  ///< + axis: int16 mm/s
inline constexpr std::uint16_t kGatewayHeartbeat = 5;
inline constexpr std::uint16_t kCommandBlockStart = 0;
inline constexpr std::uint16_t kCommandBlockCount = 6;
inline constexpr std::uint16_t kWritableCount = 16;  ///< 6..15 reserved (read as 0)

// Status block: written by the PLC every cycle, read by the gateway every cycle.
inline constexpr std::uint16_t kPlcHeartbeat = 16;
inline constexpr std::uint16_t kStatusWord = 17;
inline constexpr std::uint16_t kFaultCode = 18;
inline constexpr std::uint16_t kActiveMode = 19;
inline constexpr std::uint16_t kPosition = 20;  ///< + 2 * axis: int32 mm, high word first
inline constexpr std::uint16_t kVelocity = 26;  ///< + axis: int16 mm/s
inline constexpr std::uint16_t kLoadMass = 29;  ///< uint16 kg
inline constexpr std::uint16_t kStatusBlockStart = 16;
inline constexpr std::uint16_t kStatusBlockCount = 14;

// Limits block: written by the PLC at start-up, read by the gateway after each connect.
inline constexpr std::uint16_t kMapVersion = 32;
inline constexpr std::uint16_t kMaxSpeed = 33;         ///< + axis: uint16 mm/s
inline constexpr std::uint16_t kMaxAcceleration = 36;  ///< + axis: uint16 mm/s^2
inline constexpr std::uint16_t kRatedLoad = 39;        ///< uint16 kg
inline constexpr std::uint16_t kPositionMin = 40;      ///< + 2 * axis: int32 mm, high word first
inline constexpr std::uint16_t kPositionMax = 46;      ///< + 2 * axis: int32 mm, high word first
inline constexpr std::uint16_t kLimitsBlockStart = 32;
inline constexpr std::uint16_t kLimitsBlockCount = 20;

/// Holding registers the PLC serves: 0 .. kRegisterCount - 1.
inline constexpr std::uint16_t kRegisterCount = 52;
}  // namespace reg

/// Value of the map version register for the layout in this header.
inline constexpr std::uint16_t kMapVersion = 1;

using CommandRegisters = std::array<std::uint16_t, reg::kCommandBlockCount>;
using StatusRegisters = std::array<std::uint16_t, reg::kStatusBlockCount>;
using LimitRegisters = std::array<std::uint16_t, reg::kLimitsBlockCount>;

/// Control word bits (gateway -> PLC).
namespace control_bit {
inline constexpr std::uint16_t kEnable = 1U << 0U;
inline constexpr std::uint16_t kReset = 1U << 1U;  ///< acts on the rising edge
inline constexpr std::uint16_t kExternalControlRequest = 1U << 2U;
inline constexpr std::uint16_t kKnownMask = 0x0007;
}  // namespace control_bit

/// Status word bits (PLC -> gateway).
namespace status_bit {
inline constexpr std::uint16_t kReady = 1U << 0U;
inline constexpr std::uint16_t kEnabled = 1U << 1U;
inline constexpr std::uint16_t kExternalControlGranted = 1U << 2U;
inline constexpr std::uint16_t kMoving = 1U << 3U;
inline constexpr std::uint16_t kFault = 1U << 4U;
inline constexpr std::uint16_t kEmergencyStop = 1U << 5U;
inline constexpr std::uint16_t kOverload = 1U << 6U;
inline constexpr std::uint16_t kHeartbeatFault = 1U << 7U;
/// Limit switch of `axis` at its lower (min) or upper (max) end: bit 8 + 2 * axis (+ 1 for max).
inline constexpr std::uint16_t limit_min(std::size_t axis) {
  return static_cast<std::uint16_t>(1U << (8U + 2U * axis));
}
inline constexpr std::uint16_t limit_max(std::size_t axis) {
  return static_cast<std::uint16_t>(1U << (9U + 2U * axis));
}
inline constexpr std::uint16_t kKnownMask = 0x3FFF;
}  // namespace status_bit

/// Operating mode, requested by the gateway and reported active by the PLC.
enum class CraneMode : std::uint16_t {
  kLocal = 0,             ///< the crane follows its own pendant; Modbus setpoints are ignored
  kExternalVelocity = 1,  ///< the crane follows the Modbus velocity setpoints when granted
};

/// Fault code register. Latched faults (e-stop, heartbeat timeout) take precedence; the others
/// are reported while the condition lasts.
enum class FaultCode : std::uint16_t {
  kNone = 0,
  kEmergencyStop = 1,     ///< latched until reset with the e-stop released
  kHeartbeatTimeout = 2,  ///< latched until reset
  kInvalidCommand = 3,    ///< the command block holds unknown bits or values; treated as zero
  kOverload = 4,          ///< load above the overload threshold: hoisting up is blocked
};

/// "none", "emergency_stop", …; "unknown" for values outside the enum.
std::string_view fault_code_name(FaultCode code);
/// "local", "external_velocity"; "unknown" for values outside the enum.
std::string_view mode_name(CraneMode mode);

/// Control word as flags.
struct ControlFlags {
  bool enable = false;
  bool reset = false;
  bool external_control_request = false;
  bool operator==(const ControlFlags& other) const;
};

/// The command block (gateway -> PLC) in SI units.
struct CraneCommand {
  ControlFlags control;
  CraneMode requested_mode = CraneMode::kLocal;
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();  ///< crane frame, per axis
  std::uint16_t gateway_heartbeat = 0;
};

/// Status word as flags.
struct StatusFlags {
  bool ready = false;
  bool enabled = false;
  bool external_control_granted = false;
  bool moving = false;
  bool fault = false;  ///< a latched fault is present (see fault code)
  bool emergency_stop = false;
  bool overload = false;
  bool heartbeat_fault = false;
  std::array<bool, kAxisCount> limit_min{};  ///< axis at its lower software limit
  std::array<bool, kAxisCount> limit_max{};  ///< axis at its upper software limit
  bool operator==(const StatusFlags& other) const;
};

/// The status block (PLC -> gateway) in SI units.
struct CraneStatus {
  std::uint16_t plc_heartbeat = 0;
  StatusFlags flags;
  FaultCode fault_code = FaultCode::kNone;
  CraneMode active_mode = CraneMode::kLocal;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();    ///< crane frame, hook height for z
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();  ///< crane frame
  double load_kg = 0.0;                                    ///< measured hook load
};

/// The crane's configured limits (limits block), SI units, crane frame.
struct CraneLimits {
  Eigen::Vector3d position_min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_max_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_speed_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_accel_mps2 = Eigen::Vector3d::Zero();
  double rated_load_kg = 0.0;
};

/// What a decoder considers plausible for a status block.
struct Plausibility {
  CraneLimits limits;
  /// Positions may lie this far outside the configured range (overshoot, encoder tolerance).
  double position_margin_m = 0.2;
  /// Speeds above max_speed * speed_factor are physically impossible for this crane.
  double speed_factor = 1.25;
  /// Loads above rated_load * load_factor are beyond what the hoist can lift or weigh.
  double load_factor = 2.0;
};

/// Why a register block was rejected: the register, the field it holds, what was wrong.
struct DecodeError {
  std::uint16_t register_address = 0;
  std::string field;
  std::string reason;
  /// "register 17 (status word): unknown bits 0xc000".
  std::string to_string() const;
};

/// A decoded value or the reason it was rejected.
template <typename T>
struct Decoded {
  std::optional<T> value;
  DecodeError error;

  static Decoded success(T decoded) { return Decoded{std::move(decoded), {}}; }
  static Decoded failure(std::uint16_t address, std::string field, std::string reason) {
    return Decoded{std::nullopt, DecodeError{address, std::move(field), std::move(reason)}};
  }
  explicit operator bool() const { return value.has_value(); }
};

/// Encoded registers and whether any value had to be saturated to fit its register.
template <typename Registers>
struct Encoded {
  Registers registers{};
  bool saturated = false;
};

/// A value saturated into an integer register type.
template <typename Int>
struct Saturated {
  Int value = 0;
  bool saturated = false;  ///< the input was out of range or not finite
};

// --- primitives -------------------------------------------------------------------------

/// The register holding a signed 16-bit value (two's complement).
std::uint16_t int16_to_register(std::int16_t value);
/// The signed 16-bit value held by a register (two's complement).
std::int16_t register_to_int16(std::uint16_t value);
/// A signed 32-bit value as two registers, high word first (word order "ABCD").
std::array<std::uint16_t, 2> split_int32(std::int32_t value);
/// The signed 32-bit value of two registers, high word first.
std::int32_t join_int32(std::uint16_t high, std::uint16_t low);

/// Rounds `value` to the nearest integer and saturates it to [-32768, 32767]; NaN gives 0.
Saturated<std::int16_t> saturate_int16(double value);
/// Rounds and saturates to [0, 65535]; NaN gives 0.
Saturated<std::uint16_t> saturate_uint16(double value);
/// Rounds and saturates to the int32 range; NaN gives 0.
Saturated<std::int32_t> saturate_int32(double value);

// --- blocks -----------------------------------------------------------------------------

/// Control word register value of `flags`.
std::uint16_t encode_control_word(const ControlFlags& flags);
/// Status word register value of `flags`.
std::uint16_t encode_status_word(const StatusFlags& flags);
/// Flags of a status word; unknown bits are ignored (decode_status rejects them).
StatusFlags decode_status_word(std::uint16_t word);

/// Command block of `command`: velocities in mm/s, saturated to int16 (flagged).
Encoded<CommandRegisters> encode_command(const CraneCommand& command);
/// Command block -> command. Rejects unknown control bits and unknown modes.
Decoded<CraneCommand> decode_command(const CommandRegisters& registers);

/// Status block of `status`: positions in mm (int32), velocities mm/s (int16), load kg (uint16).
Encoded<StatusRegisters> encode_status(const CraneStatus& status);
/// Status block -> status. Rejects unknown status bits, unknown modes and fault codes,
/// inconsistent flags, positions outside the range (plus margin), speeds above the physical
/// maximum and implausible loads, naming the register and the reason.
Decoded<CraneStatus> decode_status(const StatusRegisters& registers,
                                   const Plausibility& plausibility);

/// Limits block of `limits`, stamped with kMapVersion.
Encoded<LimitRegisters> encode_limits(const CraneLimits& limits);
/// Limits block -> limits. Rejects another map version, empty ranges and non-positive speeds,
/// accelerations or rated load.
Decoded<CraneLimits> decode_limits(const LimitRegisters& registers);

/// Checks that `limits` are usable (finite, min < max, positive speeds, accelerations and rated
/// load, representable in the registers). Returns the first problem, or nothing.
std::optional<std::string> check_limits(const CraneLimits& limits);

/// Compares the PLC's limits with the configured ones to within the register resolution
/// (1 mm, 1 mm/s, 1 mm/s^2, 1 kg). Returns the first difference, or nothing.
std::optional<std::string> compare_limits(const CraneLimits& plc, const CraneLimits& configured);

}  // namespace rigger::crane
