#pragma once
// The crane gateway's Modbus TCP client cycle (libmodbus), independent of DDS: the DDS node
// feeds it commands and control requests and publishes its state.

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

#include "gateway_logic.hpp"
#include "rigger/crane_protocol/modbus_context.hpp"
#include "velocity_command_filter.hpp"

namespace rigger::crane_gateway {

/// A gateway configuration that cannot work; the message names the field.
class GatewayConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Where the PLC is and how to talk to it.
struct CraneGatewayConfig {
  /// Name or address (IPv4/IPv6). Prefer a numeric address: a name is resolved at every connect.
  std::string plc_host = "127.0.0.1";
  std::uint16_t plc_port = 502;
  int unit_id = 1;
  /// Bounds connect() and every Modbus response.
  std::chrono::milliseconds response_timeout{50};
  /// The period at which the caller should call cycle() (20 ms = 50 Hz); cycle() does not pace.
  std::chrono::milliseconds cycle_period{20};
  /// Reconnect backoff: the first retry after `min`, doubling up to `max`.
  std::chrono::milliseconds reconnect_backoff_min{20};
  std::chrono::milliseconds reconnect_backoff_max{2000};
  GatewayLogicConfig logic;
};

/// Throws GatewayConfigError if `config` is unusable.
void validate(const CraneGatewayConfig& config);

/// What one cycle did.
enum class CycleOutcome {
  kOk,                   ///< status read, command written, no fault
  kPlcFault,             ///< done, but the PLC reports a latched fault
  kImplausibleState,     ///< done with zero setpoints: the status block was rejected
  kPlcHeartbeatStalled,  ///< done with zero setpoints: the PLC's heartbeat stopped
  kWaitingToReconnect,   ///< link down, next attempt not due yet
  kConnectFailed,        ///< a connection attempt failed
  kMapMismatch,          ///< connected to a PLC whose map/limits differ: disconnected again
  kLinkLost,             ///< a transaction failed: the link was dropped
};

/// "ok", "plc_fault", …
std::string_view outcome_name(CycleOutcome outcome);

/// One cycle's outcome, with the reason to log when it is not kOk/kWaitingToReconnect.
struct CycleReport {
  CycleOutcome outcome = CycleOutcome::kOk;
  std::string reason;
};

/// Time sources of the gateway, injectable for tests.
struct GatewayClocks {
  std::function<SteadyTime()> steady = [] { return std::chrono::steady_clock::now(); };
  std::function<WallTime()> wall = [] { return std::chrono::system_clock::now(); };
};

/// The Modbus TCP client of the crane PLC.
///
/// Each cycle() reads the status block, decides (GatewayLogic) and writes the command block:
/// setpoints only from fresh commands and only while the PLC grants external control, a new
/// heartbeat every cycle. A failed transaction drops the link at once (reported in the state)
/// and later cycles reconnect with exponential backoff; after a reconnect the setpoints stay
/// zero until a command stamped after the reconnect arrives.
///
/// Thread safety: cycle() must be called from one thread at a time (the cycle thread);
/// submit_command(), set_control(), request_reset() and state() may be called from any thread.
/// Nothing throws after construction.
class CraneGateway {
 public:
  /// Throws GatewayConfigError. Does not connect yet (the first cycle() does).
  explicit CraneGateway(CraneGatewayConfig config, GatewayClocks clocks = {});
  /// Releases the crane (see release()).
  ~CraneGateway();
  CraneGateway(const CraneGateway&) = delete;
  CraneGateway& operator=(const CraneGateway&) = delete;

  /// Offers a velocity command; the verdict says whether it may move the crane.
  CommandVerdict submit_command(const VelocityCommand& command);
  void set_control(const ControlRequest& control);
  /// Pulses the PLC's reset bit (clears latched faults once their cause is gone).
  void request_reset();
  /// See GatewayLogic::set_safe_stop().
  void set_safe_stop(bool active, const std::string& reason);

  /// One Modbus cycle. Never throws; blocks at most about two response timeouts.
  CycleReport cycle();
  /// If connected: writes a last command block with enable and external control off and zero
  /// setpoints (so the PLC releases the crane rather than timing out), then disconnects. The
  /// control request stays cleared; a later cycle() reconnects.
  void release();

  /// A copy of the current state.
  GatewayState state() const;
  const CraneGatewayConfig& config() const { return config_; }

 private:
  CycleReport connect(SteadyTime now, WallTime wall_now);
  CycleReport drop_link(CycleOutcome outcome, const std::string& reason, SteadyTime now);
  void back_off(SteadyTime now);

  CraneGatewayConfig config_;
  GatewayClocks clocks_;
  std::string endpoint_;  // host:port, for messages

  mutable std::mutex mutex_;  // guards logic_
  GatewayLogic logic_;

  // Touched by the cycle thread only.
  crane::ModbusContextPtr context_;
  SteadyTime next_attempt_{};
  std::chrono::milliseconds backoff_;
};

}  // namespace rigger::crane_gateway
