#include "rigger/plc/plc_program.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace rigger::plc {
namespace {

using crane::CraneMode;
using crane::FaultCode;

constexpr auto kMaxHeartbeatTimeout = std::chrono::milliseconds(250);

// Highest speed from which the axis can still stop, decelerating at `accel_mps2`, before it
// travels `distance_m`: the braking curve v = sqrt(2 a d) a real crane's pre-limit switch
// approximates.
double braking_curve_mps(double distance_m, double accel_mps2) {
  return distance_m <= 0.0 ? 0.0 : std::sqrt(2.0 * accel_mps2 * distance_m);
}

}  // namespace

void validate(const PlcProgramConfig& config) {
  if (const auto problem = crane::check_limits(config.limits)) {
    throw PlcConfigError("plc limits: " + *problem);
  }
  if (config.heartbeat_timeout <= std::chrono::nanoseconds::zero() ||
      config.heartbeat_timeout > kMaxHeartbeatTimeout) {
    throw PlcConfigError("plc heartbeat_timeout: must be in (0, 250] ms");
  }
  for (std::size_t axis = 0; axis < crane::kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const double quick = config.quick_stop_decel_mps2[i];
    if (!std::isfinite(quick) || quick < config.limits.max_accel_mps2[i]) {
      throw PlcConfigError("plc quick_stop_decel_mps2 " + std::string(crane::axis_name(axis)) +
                           ": must be finite and at least the axis' max acceleration");
    }
    if (config.stop_decel_mps2) {
      const double stop = (*config.stop_decel_mps2)[i];
      if (!std::isfinite(stop) || stop < config.limits.max_accel_mps2[i] || stop > quick) {
        throw PlcConfigError("plc stop_decel_mps2 " + std::string(crane::axis_name(axis)) +
                             ": must be between the axis' max acceleration and its quick stop deceleration");
      }
    }
    const double range = config.limits.position_max_m[i] - config.limits.position_min_m[i];
    if (!(config.limit_switch_tolerance_m >= 0.0) ||
        !(2.0 * config.limit_switch_tolerance_m < range)) {
      throw PlcConfigError("plc limit_switch_tolerance_m: must be >= 0 and below half the " +
                           std::string(crane::axis_name(axis)) + " range");
    }
  }
  if (!(config.overload_factor >= 1.0) || !std::isfinite(config.overload_factor)) {
    throw PlcConfigError("plc overload_factor: must be finite and >= 1");
  }
  if (!(config.moving_threshold_mps > 0.0) || !std::isfinite(config.moving_threshold_mps)) {
    throw PlcConfigError("plc moving_threshold_mps: must be finite and positive");
  }
}

PlcProgram::PlcProgram(PlcProgramConfig config) : config_(std::move(config)) { validate(config_); }

void PlcProgram::latch(FaultCode code) {
  if (first_fault_ == FaultCode::kNone) {
    first_fault_ = code;
  }
  if (code == FaultCode::kEmergencyStop) {
    estop_latched_ = true;
  } else if (code == FaultCode::kHeartbeatTimeout) {
    heartbeat_fault_ = true;
  }
}

PlcOutputs PlcProgram::cycle(const PlcInputs& inputs, std::chrono::nanoseconds dt) {
  const bool advance = dt > std::chrono::nanoseconds::zero();
  if (advance) {
    time_ += dt;
  }
  const double dt_s = advance ? std::chrono::duration<double>(dt).count() : 0.0;
  ++plc_heartbeat_;

  // An invalid command block counts as "everything off": a PLC must not guess what garbage meant.
  const bool command_valid = inputs.command.has_value();
  const crane::CraneCommand command = command_valid ? *inputs.command : crane::CraneCommand{};
  const crane::ControlFlags& control = command.control;
  const CraneAxesMeasurement& measured = inputs.measured;
  const crane::CraneLimits& limits = config_.limits;

  // Reset acts on the rising edge so that a reset bit stuck at 1 cannot mask new faults, and
  // only with the e-stop released.
  const bool reset_edge = control.reset && !previous_reset_;
  previous_reset_ = control.reset;
  if (reset_edge && !estop_input_) {
    estop_latched_ = false;
    heartbeat_fault_ = false;
    first_fault_ = FaultCode::kNone;
    last_heartbeat_change_ = time_;
  }
  if (estop_input_) {
    latch(FaultCode::kEmergencyStop);
  }

  // Heartbeat watchdog: armed while the gateway holds the crane. The control word it last wrote
  // stays in the registers when the link dies, so a dead gateway keeps the watchdog armed.
  if (inputs.gateway_heartbeat != last_gateway_heartbeat_) {
    last_gateway_heartbeat_ = inputs.gateway_heartbeat;
    last_heartbeat_change_ = time_;
  }
  const bool gateway_holds = control.enable || control.external_control_request || enabled_;
  if (!gateway_holds) {
    watchdog_armed_ = false;
  } else if (!watchdog_armed_) {
    watchdog_armed_ = true;
    last_heartbeat_change_ = time_;
  } else if (time_ - last_heartbeat_change_ > config_.heartbeat_timeout) {
    latch(FaultCode::kHeartbeatTimeout);
  }

  // Enable: level-sensitive, dropped by any fault; (re-)enabling needs zero setpoints so that
  // a reset never restarts motion by itself.
  if (faulted() || !control.enable || !command_valid) {
    enabled_ = false;
  } else if (!enabled_ && command.velocity_mps.isZero(0.0)) {
    enabled_ = true;
  }
  const bool granted = enabled_ && control.external_control_request &&
                       command.requested_mode == CraneMode::kExternalVelocity;

  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  if (granted) {
    target = command.velocity_mps.cwiseMax(-limits.max_speed_mps).cwiseMin(limits.max_speed_mps);
  }
  const bool overload = measured.load_kg > limits.rated_load_kg * config_.overload_factor;
  if (overload && target.z() > 0.0) {
    target.z() = 0.0;  // an overload limiter blocks hoisting; lowering stays possible
  }

  const double tolerance = config_.limit_switch_tolerance_m;
  PlcOutputs out;
  crane::StatusFlags& flags = out.status.flags;
  for (std::size_t axis = 0; axis < crane::kAxisCount; ++axis) {
    const auto i = static_cast<Eigen::Index>(axis);
    const double position = measured.position_m[i];
    const double to_max = limits.position_max_m[i] - tolerance - position;
    const double to_min = position - (limits.position_min_m[i] + tolerance);
    const double accel = limits.max_accel_mps2[i];
    if (target[i] > 0.0) {
      target[i] = std::min(target[i], braking_curve_mps(to_max, accel));
    } else if (target[i] < 0.0) {
      target[i] = std::max(target[i], -braking_curve_mps(to_min, accel));
    }
    flags.limit_max[axis] = to_max <= 0.0;
    flags.limit_min[axis] = to_min <= 0.0;

    // Ramp generator. Faults and overrun limits stop with the quick-stop deceleration.
    const bool overrun = (flags.limit_max[axis] && ramp_velocity_mps_[i] > 0.0) ||
                         (flags.limit_min[axis] && ramp_velocity_mps_[i] < 0.0);
    const double current = ramp_velocity_mps_[i];
    const bool slowing = std::abs(target[i]) < std::abs(current) || target[i] * current < 0.0;
    const double ramp = slowing && config_.stop_decel_mps2 ? (*config_.stop_decel_mps2)[i] : accel;
    const double rate = (faulted() || overrun) ? config_.quick_stop_decel_mps2[i] : ramp;
    const double max_step = rate * dt_s;
    ramp_velocity_mps_[i] += std::clamp(target[i] - ramp_velocity_mps_[i], -max_step, max_step);
  }
  out.velocity_command_mps = ramp_velocity_mps_;

  const double moving = config_.moving_threshold_mps;
  crane::CraneStatus& status = out.status;
  status.plc_heartbeat = plc_heartbeat_;
  flags.ready = !faulted() && !estop_input_;
  flags.enabled = enabled_;
  flags.external_control_granted = granted;
  flags.moving = measured.velocity_mps.cwiseAbs().maxCoeff() > moving ||
                 ramp_velocity_mps_.cwiseAbs().maxCoeff() > moving;
  flags.fault = faulted();
  flags.emergency_stop = estop_latched_;
  flags.overload = overload;
  flags.heartbeat_fault = heartbeat_fault_;
  if (faulted()) {
    status.fault_code = first_fault_;
  } else if (!command_valid) {
    status.fault_code = FaultCode::kInvalidCommand;
  } else if (overload) {
    status.fault_code = FaultCode::kOverload;
  } else {
    status.fault_code = FaultCode::kNone;
  }
  status.active_mode = granted ? CraneMode::kExternalVelocity : CraneMode::kLocal;
  status.position_m = measured.position_m;
  status.velocity_mps = measured.velocity_mps;
  status.load_kg = measured.load_kg;
  return out;
}

}  // namespace rigger::plc
