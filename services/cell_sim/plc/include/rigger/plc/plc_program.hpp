#pragma once
// The crane PLC program as pure logic, cycled with a dt (docs/crane-modbus.md, "PLC program").
//
// No sockets, no threads, no clocks: the program's time is the sum of the dt it was cycled
// with, so tests can drive it deterministically.

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>

#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/plc/crane_axes_io.hpp"

namespace rigger::plc {

/// A PLC configuration that cannot work; the message names the field.
class PlcConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Parameters of the PLC program.
struct PlcProgramConfig {
  crane::CraneLimits limits;
  /// The gateway's heartbeat register must change within this time while the gateway holds the
  /// crane (enable or external control requested). At most 250 ms.
  std::chrono::nanoseconds heartbeat_timeout = std::chrono::milliseconds(200);
  /// Deceleration of the quick stop after a fault (e-stop, heartbeat timeout) [m/s^2], per axis.
  Eigen::Vector3d quick_stop_decel_mps2{2.0, 2.0, 1.0};
  /// Deceleration ramp [m/s^2], per axis, used while the setpoint asks the axis to slow down (a frequency
  /// converter's separate deceleration ramp); between the axis' max acceleration and its quick stop.
  /// Nothing: the max acceleration, as when speeding up.
  std::optional<Eigen::Vector3d> stop_decel_mps2;
  /// Overload when the hook load exceeds rated_load * overload_factor.
  double overload_factor = 1.1;
  /// A limit switch is active within this distance of its end of range [m].
  double limit_switch_tolerance_m = 0.002;
  /// Speed above which an axis counts as moving [m/s].
  double moving_threshold_mps = 0.005;
};

/// Throws PlcConfigError if `config` is unusable.
void validate(const PlcProgramConfig& config);

/// One cycle's inputs.
struct PlcInputs {
  /// The decoded command block; nothing if it held unknown bits or values (then the PLC acts
  /// as if everything were off and reports FaultCode::kInvalidCommand).
  std::optional<crane::CraneCommand> command;
  /// The raw gateway heartbeat register (watched even when the rest of the block is invalid).
  std::uint16_t gateway_heartbeat = 0;
  CraneAxesMeasurement measured;
};

/// One cycle's outputs.
struct PlcOutputs {
  Eigen::Vector3d velocity_command_mps = Eigen::Vector3d::Zero();  ///< to the drives
  crane::CraneStatus status;                                       ///< to the status block
};

/// The crane PLC program: enable/reset handshake, external-control grant, speed and
/// acceleration ramps, heartbeat watchdog, software limit switches, e-stop, overload.
/// Not thread-safe: the owner serialises calls.
class PlcProgram {
 public:
  /// Throws PlcConfigError.
  explicit PlcProgram(PlcProgramConfig config);

  /// Runs one cycle of length `dt` (> 0; a non-positive dt runs the logic without advancing
  /// time or ramps).
  PlcOutputs cycle(const PlcInputs& inputs, std::chrono::nanoseconds dt);

  /// The e-stop input (a mushroom button): pressed stops the crane and latches the e-stop
  /// fault; it clears only with a reset while released.
  void set_emergency_stop(bool pressed) { estop_input_ = pressed; }
  bool emergency_stop_pressed() const { return estop_input_; }

  /// Program time: the sum of the cycles' dt.
  std::chrono::nanoseconds time() const { return time_; }
  const PlcProgramConfig& config() const { return config_; }

 private:
  void latch(crane::FaultCode code);
  bool faulted() const { return estop_latched_ || heartbeat_fault_; }

  PlcProgramConfig config_;
  std::chrono::nanoseconds time_{0};
  std::uint16_t plc_heartbeat_ = 0;

  bool estop_input_ = false;
  bool estop_latched_ = false;
  bool heartbeat_fault_ = false;
  crane::FaultCode first_fault_ = crane::FaultCode::kNone;

  bool previous_reset_ = false;
  bool watchdog_armed_ = false;
  std::uint16_t last_gateway_heartbeat_ = 0;
  std::chrono::nanoseconds last_heartbeat_change_{0};

  bool enabled_ = false;
  Eigen::Vector3d ramp_velocity_mps_ = Eigen::Vector3d::Zero();
};

}  // namespace rigger::plc
