#include "gateway_logic.hpp"

#include <stdexcept>

namespace rigger::crane_gateway {

std::string_view fault_name(GatewayFault fault) {
  switch (fault) {
    case GatewayFault::kNone:
      return "none";
    case GatewayFault::kLinkDown:
      return "link_down";
    case GatewayFault::kPlcMapMismatch:
      return "plc_map_mismatch";
    case GatewayFault::kImplausibleState:
      return "implausible_state";
    case GatewayFault::kPlcHeartbeatStalled:
      return "plc_heartbeat_stalled";
    case GatewayFault::kPlcFault:
      return "plc_fault";
  }
  return "unknown";
}

GatewayLogic::GatewayLogic(GatewayLogicConfig config)
    : config_(std::move(config)), filter_(config_.command_timeout, config_.max_command_future) {
  if (const auto problem = crane::check_limits(config_.plausibility.limits)) {
    throw std::invalid_argument("crane limits: " + *problem);
  }
  if (config_.plc_heartbeat_timeout <= std::chrono::nanoseconds::zero()) {
    throw std::invalid_argument("plc heartbeat timeout must be positive");
  }
  if (config_.reset_pulse_cycles < 1) {
    throw std::invalid_argument("reset pulse must last at least one cycle");
  }
}

CommandVerdict GatewayLogic::submit(const VelocityCommand& command, WallTime now) {
  const CommandVerdict verdict = state_.safe_stop ? CommandVerdict::kSafeStop : filter_.offer(command, now);
  if (verdict != CommandVerdict::kAccepted) {
    ++state_.rejected_commands;
  }
  return verdict;
}

void GatewayLogic::set_control(const ControlRequest& control) { state_.control = control; }

void GatewayLogic::request_reset() { reset_cycles_left_ = config_.reset_pulse_cycles; }

void GatewayLogic::set_safe_stop(bool active, const std::string& reason, WallTime now) {
  filter_.reset(now);
  state_.safe_stop = active;
  state_.safe_stop_reason = active ? reason : "";
}

void GatewayLogic::set_fault(GatewayFault fault, std::string reason) {
  state_.fault = fault;
  state_.fault_reason = std::move(reason);
}

std::optional<std::string> GatewayLogic::on_connected(const crane::LimitRegisters& limits,
                                                      WallTime wall_now, SteadyTime now) {
  state_.external_control_granted = false;
  const auto decoded = crane::decode_limits(limits);
  std::optional<std::string> mismatch;
  if (!decoded) {
    mismatch = "PLC limits block rejected: " + decoded.error.to_string();
  } else if (const auto difference =
                 crane::compare_limits(*decoded.value, config_.plausibility.limits)) {
    mismatch = "PLC limits differ from the configuration: " + *difference;
  }
  if (mismatch) {
    state_.link_up = false;
    set_fault(GatewayFault::kPlcMapMismatch, *mismatch);
    return mismatch;
  }
  state_.plc_limits = decoded.value;
  state_.link_up = true;
  state_.link_changed = now;
  ++state_.connects;
  set_fault(GatewayFault::kNone, {});
  // Whatever arrived before the link came up belongs to a situation that no longer exists.
  filter_.reset(wall_now);
  last_plc_heartbeat_.reset();
  return std::nullopt;
}

void GatewayLogic::on_link_lost(const std::string& reason, SteadyTime now) {
  if (state_.link_up) {
    ++state_.link_losses;
    state_.link_changed = now;
  }
  state_.link_up = false;
  state_.external_control_granted = false;
  state_.setpoint_mps.setZero();
  set_fault(GatewayFault::kLinkDown, reason);
}

GatewayFault GatewayLogic::on_status(const crane::StatusRegisters& registers, SteadyTime now) {
  state_.external_control_granted = false;
  const auto decoded = crane::decode_status(registers, config_.plausibility);
  if (!decoded) {
    ++state_.implausible_states;
    set_fault(GatewayFault::kImplausibleState,
              "implausible PLC state: " + decoded.error.to_string());
    return state_.fault;
  }
  const crane::CraneStatus& status = *decoded.value;
  if (!last_plc_heartbeat_ || *last_plc_heartbeat_ != status.plc_heartbeat) {
    last_plc_heartbeat_ = status.plc_heartbeat;
    last_plc_heartbeat_change_ = now;
  }
  state_.plc = status;
  state_.plc_time = now;
  if (now - last_plc_heartbeat_change_ > config_.plc_heartbeat_timeout) {
    set_fault(GatewayFault::kPlcHeartbeatStalled,
              "PLC heartbeat stuck at " + std::to_string(status.plc_heartbeat));
    return state_.fault;
  }
  state_.external_control_granted = status.flags.external_control_granted;
  if (status.flags.fault) {
    set_fault(GatewayFault::kPlcFault,
              "PLC fault " + std::string(crane::fault_code_name(status.fault_code)));
  } else {
    set_fault(GatewayFault::kNone, {});
  }
  return state_.fault;
}

crane::CommandRegisters GatewayLogic::next_command(WallTime wall_now) {
  crane::CraneCommand command;
  command.control.enable = state_.control.enable;
  command.control.external_control_request = state_.control.external_control;
  command.requested_mode = state_.control.external_control ? crane::CraneMode::kExternalVelocity
                                                           : crane::CraneMode::kLocal;
  if (reset_cycles_left_ > 0) {
    command.control.reset = true;
    --reset_cycles_left_;
  }
  Eigen::Vector3d setpoint = Eigen::Vector3d::Zero();
  // Our own request counts too: the PLC's grant lags our request by a cycle when it is withdrawn.
  if (state_.external_control_granted && state_.control.external_control && state_.link_up) {
    const Eigen::Vector3d& max = config_.plausibility.limits.max_speed_mps;
    const Eigen::Vector3d wanted = filter_.setpoint(wall_now);
    setpoint = wanted.cwiseMax(-max).cwiseMin(max);
    if (setpoint != wanted) {
      ++state_.clamped_setpoints;
    }
  }
  command.velocity_mps = setpoint;
  command.gateway_heartbeat = ++state_.gateway_heartbeat;
  state_.setpoint_mps = setpoint;
  ++state_.cycles;
  // Setpoints are clamped to the max speed, far inside int16 mm/s: nothing can saturate here.
  return crane::encode_command(command).registers;
}

}  // namespace rigger::crane_gateway
