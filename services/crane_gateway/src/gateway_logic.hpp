#pragma once
// The crane gateway's decisions, apart from the wire: what to write to the PLC each cycle and
// what to make of what it answered (docs/crane-modbus.md, "Gateway").

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "rigger/crane_protocol/register_map.hpp"
#include "velocity_command_filter.hpp"

namespace rigger::crane_gateway {

using SteadyTime = std::chrono::steady_clock::time_point;

/// Parameters of the gateway logic.
struct GatewayLogicConfig {
  /// The crane's limits (must match the PLC's limits block) and the plausibility margins.
  crane::Plausibility plausibility;
  /// A velocity command older than this is never applied.
  std::chrono::nanoseconds command_timeout = std::chrono::milliseconds(100);
  /// How far a command's stamp may lie ahead of our clock (clock skew between hosts).
  std::chrono::nanoseconds max_command_future = std::chrono::milliseconds(50);
  /// The PLC's heartbeat register must change within this time.
  std::chrono::nanoseconds plc_heartbeat_timeout = std::chrono::milliseconds(250);
  /// Cycles the reset bit is held high after request_reset() (the PLC acts on the rising edge).
  int reset_pulse_cycles = 3;
};

/// What the operator (or a skill) wants from the crane.
struct ControlRequest {
  bool enable = false;            ///< drives on
  bool external_control = false;  ///< follow our velocity setpoints (mode external velocity)
  bool operator==(const ControlRequest& other) const {
    return enable == other.enable && external_control == other.external_control;
  }
};

/// The gateway's fault, most severe first.
enum class GatewayFault {
  kNone,
  kLinkDown,             ///< no Modbus connection to the PLC
  kPlcMapMismatch,       ///< the PLC's map version or limits differ from our configuration
  kImplausibleState,     ///< the PLC's status block failed the plausibility checks
  kPlcHeartbeatStalled,  ///< the PLC's heartbeat register stopped changing
  kPlcFault,             ///< the PLC reports a latched fault (e-stop, heartbeat timeout)
};

/// "none", "link_down", …
std::string_view fault_name(GatewayFault fault);

/// Everything the gateway knows, for publishing.
struct GatewayState {
  bool link_up = false;
  GatewayFault fault = GatewayFault::kLinkDown;
  std::string fault_reason = "not connected yet";
  /// The last plausible status block and when it was read (kept across a link loss: check
  /// link_up and plc_time before trusting it).
  std::optional<crane::CraneStatus> plc;
  SteadyTime plc_time{};
  /// The PLC's limits block as read at the last connect.
  std::optional<crane::CraneLimits> plc_limits;
  /// Whether our setpoints currently drive the crane: link up, plausible and live status with
  /// external control granted.
  bool external_control_granted = false;
  ControlRequest control;                                  ///< what we ask the PLC for
  Eigen::Vector3d setpoint_mps = Eigen::Vector3d::Zero();  ///< last setpoint written
  std::uint16_t gateway_heartbeat = 0;                     ///< last heartbeat written
  SteadyTime link_changed{};  ///< when link_up last changed (connect or loss)
  std::uint64_t cycles = 0;   ///< command blocks produced
  std::uint64_t connects = 0;
  std::uint64_t link_losses = 0;
  std::uint64_t implausible_states = 0;  ///< status blocks rejected
  std::uint64_t rejected_commands = 0;   ///< velocity commands not accepted
  std::uint64_t clamped_setpoints = 0;   ///< setpoints limited to the max speed
  /// A software safe stop of the crane is in force: setpoints are zero and commands refused until
  /// it is reset. Its reason ("" when none).
  bool safe_stop = false;
  std::string safe_stop_reason;
};

/// The gateway's logic: command freshness, the grant, heartbeats in both directions, reset
/// pulses, plausibility of what the PLC reports. Pure: no sockets, no clocks, no logging; the
/// caller passes the time and does the I/O. Not thread-safe.
class GatewayLogic {
 public:
  /// Throws std::invalid_argument (bad timeouts, pulse length, or limits).
  explicit GatewayLogic(GatewayLogicConfig config);

  /// Offers a velocity command (see VelocityCommandFilter for the rules).
  CommandVerdict submit(const VelocityCommand& command, WallTime now);
  void set_control(const ControlRequest& control);
  /// Pulses the reset bit for reset_pulse_cycles written cycles.
  void request_reset();
  /// A safe stop (active) forgets the current command at once, so the next command block carries a
  /// zero setpoint, and refuses every command (kSafeStop) until it is reset (active = false); only
  /// commands stamped after the reset count then.
  void set_safe_stop(bool active, const std::string& reason, WallTime now);

  /// A connection is up and the PLC's limits block was read. Returns the reason if the PLC's
  /// map version or limits do not match ours (then the caller must drop the connection and
  /// write nothing). Otherwise forgets every command received so far: only commands stamped
  /// after `wall_now` will move the crane.
  std::optional<std::string> on_connected(const crane::LimitRegisters& limits, WallTime wall_now,
                                          SteadyTime now);
  /// The connection is gone (or was refused). Revokes the grant.
  void on_link_lost(const std::string& reason, SteadyTime now);
  /// The status block read this cycle. Returns the resulting fault (kNone when all is well).
  GatewayFault on_status(const crane::StatusRegisters& registers, SteadyTime now);
  /// The command block to write this cycle; increments the heartbeat.
  crane::CommandRegisters next_command(WallTime wall_now);

  const GatewayState& state() const { return state_; }
  const GatewayLogicConfig& config() const { return config_; }

 private:
  void set_fault(GatewayFault fault, std::string reason);

  GatewayLogicConfig config_;
  VelocityCommandFilter filter_;
  GatewayState state_;
  int reset_cycles_left_ = 0;
  std::optional<std::uint16_t> last_plc_heartbeat_;
  SteadyTime last_plc_heartbeat_change_{};
};

}  // namespace rigger::crane_gateway
