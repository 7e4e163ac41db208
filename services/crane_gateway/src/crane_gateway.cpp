#include "crane_gateway.hpp"

#include <cerrno>

namespace rigger::crane_gateway {
namespace {

namespace reg = crane::reg;

std::string error_text(const char* what, int errnum) {
  return std::string(what) + ": " + crane::modbus_error_text(errnum);
}

}  // namespace

std::string_view outcome_name(CycleOutcome outcome) {
  switch (outcome) {
    case CycleOutcome::kOk:
      return "ok";
    case CycleOutcome::kPlcFault:
      return "plc_fault";
    case CycleOutcome::kImplausibleState:
      return "implausible_state";
    case CycleOutcome::kPlcHeartbeatStalled:
      return "plc_heartbeat_stalled";
    case CycleOutcome::kWaitingToReconnect:
      return "waiting_to_reconnect";
    case CycleOutcome::kConnectFailed:
      return "connect_failed";
    case CycleOutcome::kMapMismatch:
      return "map_mismatch";
    case CycleOutcome::kLinkLost:
      return "link_lost";
  }
  return "unknown";
}

void validate(const CraneGatewayConfig& config) {
  if (config.plc_host.empty()) {
    throw GatewayConfigError("plc_host: must not be empty");
  }
  if (config.plc_port == 0) {
    throw GatewayConfigError("plc_port: must not be 0");
  }
  if (!((config.unit_id >= 0 && config.unit_id <= 247) || config.unit_id == 255)) {
    throw GatewayConfigError("unit_id: must be 0..247 or 255");
  }
  if (config.response_timeout <= std::chrono::milliseconds::zero()) {
    throw GatewayConfigError("response_timeout: must be positive");
  }
  if (config.cycle_period <= std::chrono::milliseconds::zero()) {
    throw GatewayConfigError("cycle_period: must be positive");
  }
  if (config.reconnect_backoff_min <= std::chrono::milliseconds::zero() ||
      config.reconnect_backoff_max < config.reconnect_backoff_min) {
    throw GatewayConfigError("reconnect_backoff: need 0 < min <= max");
  }
  if (config.logic.command_timeout < config.cycle_period) {
    throw GatewayConfigError("command_timeout: must be at least one cycle period");
  }
  try {
    GatewayLogic{config.logic};
  } catch (const std::invalid_argument& e) {
    throw GatewayConfigError(std::string("logic: ") + e.what());
  }
}

CraneGateway::CraneGateway(CraneGatewayConfig config, GatewayClocks clocks)
    : config_((validate(config), std::move(config))),
      clocks_(std::move(clocks)),
      endpoint_(config_.plc_host + ":" + std::to_string(config_.plc_port)),
      logic_(config_.logic),
      backoff_(config_.reconnect_backoff_min) {
  next_attempt_ = clocks_.steady();
}

CraneGateway::~CraneGateway() { release(); }

CommandVerdict CraneGateway::submit_command(const VelocityCommand& command) {
  const WallTime now = clocks_.wall();
  const std::lock_guard<std::mutex> lock(mutex_);
  return logic_.submit(command, now);
}

void CraneGateway::set_control(const ControlRequest& control) {
  const std::lock_guard<std::mutex> lock(mutex_);
  logic_.set_control(control);
}

void CraneGateway::set_safe_stop(bool active, const std::string& reason) {
  const WallTime now = clocks_.wall();
  const std::lock_guard<std::mutex> lock(mutex_);
  logic_.set_safe_stop(active, reason, now);
}

void CraneGateway::request_reset() {
  const std::lock_guard<std::mutex> lock(mutex_);
  logic_.request_reset();
}

GatewayState CraneGateway::state() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return logic_.state();
}

void CraneGateway::back_off(SteadyTime now) {
  next_attempt_ = now + backoff_;
  backoff_ = std::min(backoff_ * 2, config_.reconnect_backoff_max);
}

CycleReport CraneGateway::drop_link(CycleOutcome outcome, const std::string& reason,
                                    SteadyTime now) {
  context_.reset();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    logic_.on_link_lost(reason, now);
  }
  back_off(now);
  return {outcome, reason};
}

CycleReport CraneGateway::connect(SteadyTime now, WallTime wall_now) {
  crane::ModbusContextPtr context;
  try {
    context = crane::make_tcp_client(config_.plc_host, config_.plc_port, config_.response_timeout,
                                     config_.unit_id);
  } catch (const crane::ModbusError& e) {
    return drop_link(CycleOutcome::kConnectFailed, e.what(), now);
  }
  if (modbus_connect(context.get()) != 0) {
    return drop_link(CycleOutcome::kConnectFailed,
                     error_text(("connect to " + endpoint_).c_str(), errno), now);
  }
  // Identify the device before writing anything to it: a gateway pointed at the wrong PLC, or at
  // one configured for another crane, must not write setpoints.
  crane::LimitRegisters limits{};
  if (modbus_read_registers(context.get(), reg::kLimitsBlockStart, reg::kLimitsBlockCount,
                            limits.data()) != reg::kLimitsBlockCount) {
    return drop_link(CycleOutcome::kConnectFailed,
                     error_text(("read limits block of " + endpoint_).c_str(), errno), now);
  }
  std::optional<std::string> mismatch;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    mismatch = logic_.on_connected(limits, wall_now, now);
  }
  if (mismatch) {
    context.reset();
    back_off(now);
    return {CycleOutcome::kMapMismatch, *mismatch};
  }
  context_ = std::move(context);
  return {CycleOutcome::kOk, {}};
}

CycleReport CraneGateway::cycle() {
  const SteadyTime now = clocks_.steady();
  const WallTime wall_now = clocks_.wall();
  if (!context_) {
    if (now < next_attempt_) {
      return {CycleOutcome::kWaitingToReconnect, {}};
    }
    CycleReport connected = connect(now, wall_now);
    if (!context_) {
      return connected;
    }
  }

  crane::StatusRegisters status{};
  if (modbus_read_registers(context_.get(), reg::kStatusBlockStart, reg::kStatusBlockCount,
                            status.data()) != reg::kStatusBlockCount) {
    return drop_link(CycleOutcome::kLinkLost, error_text("read status block", errno), now);
  }
  GatewayFault fault = GatewayFault::kNone;
  std::string reason;
  crane::CommandRegisters command{};
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    fault = logic_.on_status(status, now);
    reason = logic_.state().fault_reason;
    command = logic_.next_command(wall_now);
  }
  if (modbus_write_registers(context_.get(), reg::kCommandBlockStart, reg::kCommandBlockCount,
                             command.data()) != reg::kCommandBlockCount) {
    return drop_link(CycleOutcome::kLinkLost, error_text("write command block", errno), now);
  }
  backoff_ = config_.reconnect_backoff_min;

  switch (fault) {
    case GatewayFault::kNone:
      return {CycleOutcome::kOk, {}};
    case GatewayFault::kImplausibleState:
      return {CycleOutcome::kImplausibleState, reason};
    case GatewayFault::kPlcHeartbeatStalled:
      return {CycleOutcome::kPlcHeartbeatStalled, reason};
    default:
      return {CycleOutcome::kPlcFault, reason};
  }
}

void CraneGateway::release() {
  if (!context_) {
    return;
  }
  std::uint16_t heartbeat = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    logic_.set_control(ControlRequest{});
    heartbeat = static_cast<std::uint16_t>(logic_.state().gateway_heartbeat + 1);
  }
  crane::CraneCommand off;  // enable and external control off, zero setpoints
  off.gateway_heartbeat = heartbeat;
  const auto registers = crane::encode_command(off).registers;
  // Best effort: the PLC's watchdog covers the case where this write is lost.
  modbus_write_registers(context_.get(), reg::kCommandBlockStart, reg::kCommandBlockCount,
                         registers.data());
  const SteadyTime now = clocks_.steady();
  context_.reset();
  const std::lock_guard<std::mutex> lock(mutex_);
  logic_.on_link_lost("released", now);
}

}  // namespace rigger::crane_gateway
