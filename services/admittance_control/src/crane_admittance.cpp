#include "crane_admittance.hpp"

#include <cmath>
#include <utility>

#include "config_checks.hpp"
#include "rigger/base/config.hpp"

namespace rigger::control {
namespace {

Eigen::Matrix<double, 3, 2> to_matrix(const CraneGains& gains) {
  Eigen::Matrix<double, 3, 2> m;
  m << gains.mass_kg, gains.damping_ns_per_m;
  return m;
}

}  // namespace

std::string_view to_string(CraneState state) {
  switch (state) {
    case CraneState::kDisabled: return "DISABLED";
    case CraneState::kStopping: return "STOPPING";
    case CraneState::kActive: return "ACTIVE";
    case CraneState::kFault: return "FAULT";
  }
  return "?";
}

std::string_view to_string(CraneFault fault) {
  switch (fault) {
    case CraneFault::kNone: return "NONE";
    case CraneFault::kForceStale: return "FORCE_STALE";
    case CraneFault::kForceNotFinite: return "FORCE_NOT_FINITE";
    case CraneFault::kForceImplausible: return "FORCE_IMPLAUSIBLE";
    case CraneFault::kInputInvalid: return "INPUT_INVALID";
    case CraneFault::kTimeStepInvalid: return "TIME_STEP_INVALID";
  }
  return "?";
}

std::optional<ConfigProblem> find_problem(const CraneGains& gains) {
  if (auto p = check_axes(gains.mass_kg, "/mass_kg", Bound::kPositive, "kg")) return p;
  return check_axes(gains.damping_ns_per_m, "/damping_ns_per_m", Bound::kPositive, "N s/m");
}

std::optional<ConfigProblem> find_problem(const CraneAdmittanceConfig& c) {
  if (auto p = prefixed(find_problem(c.gains), "/gains")) return p;
  if (auto p = check_axes(c.deadband_n, "/deadband_n", Bound::kNonNegative, "N")) return p;
  if (auto p = check_scalar(c.force_filter_cutoff_hz, "/force_filter_cutoff_hz", Bound::kNonNegative, "Hz")) return p;
  if (auto p = check_axes(c.max_speed_mps, "/max_speed_mps", Bound::kNonNegative, "m/s")) return p;
  if (auto p = check_axes(c.max_acceleration_mps2, "/max_acceleration_mps2", Bound::kPositive, "m/s^2")) return p;
  if (auto p = check_axes(c.stop_deceleration_mps2, "/stop_deceleration_mps2", Bound::kPositive, "m/s^2")) return p;
  if (!(c.robot_velocity_feedforward >= 0.0 && c.robot_velocity_feedforward <= 1.0))
    return ConfigProblem{"/robot_velocity_feedforward", "expected a number in [0, 1]"};
  if (auto p = check_scalar(c.rope_offset_gain_per_s, "/rope_offset_gain_per_s", Bound::kNonNegative, "1/s")) return p;
  if (auto p = check_scalar(c.force_timeout.count(), "/force_timeout_s", Bound::kPositive, "s")) return p;
  if (auto p = check_scalar(c.max_time_step.count(), "/max_time_step_s", Bound::kPositive, "s")) return p;
  if (auto p = check_scalar(c.max_plausible_force_n, "/max_plausible_force_n", Bound::kPositive, "N")) return p;
  return check_scalar(c.gain_transition_time.count(), "/gain_transition_time_s", Bound::kNonNegative, "s");
}

std::array<double, 3> to_crane_axes(const Eigen::Vector3d& velocity_world_mps) {
  return {velocity_world_mps.x(), velocity_world_mps.y(), -velocity_world_mps.z()};
}

CraneAdmittance::CraneAdmittance(CraneAdmittanceConfig config)
    : config_(std::move(config)), gains_(to_matrix(config_.gains)) {
  if (auto p = find_problem(config_)) throw ConfigError("CraneAdmittanceConfig", p->pointer, p->problem);
}

void CraneAdmittance::set_enabled(bool enabled) {
  latched_fault_ = CraneFault::kNone;
  if (enabled && !enabled_) {
    // Continue from the remainder of a stop ramp, if any, without a jump.
    admittance_velocity_ = last_output_;
    filtered_force_.setZero();
  }
  enabled_ = enabled;
}

RequestResult CraneAdmittance::set_gains(const CraneGains& gains) {
  if (auto p = find_problem(gains)) return {false, "gains" + p->pointer + ": " + p->problem};
  gains_.set_target(to_matrix(gains), config_.gain_transition_time);
  return {};
}

CraneGains CraneAdmittance::current_gains() const {
  return CraneGains{gains_.current().col(0), gains_.current().col(1)};
}

void CraneAdmittance::reset_state() {
  admittance_velocity_.setZero();
  filtered_force_.setZero();
  last_output_.setZero();
}

CraneOutput CraneAdmittance::fault_output(CraneFault fault, bool latch) {
  // Zero at once: the PLC ramps the drives down with its own limits.
  if (latch) latched_fault_ = fault;
  reset_state();
  CraneOutput out;
  out.status.state = CraneState::kFault;
  out.status.fault = fault;
  out.status.fault_latched = latch;
  out.status.gains_blending = gains_.blending();
  return out;
}

CraneOutput CraneAdmittance::step(Seconds dt, const CraneInput& input) {
  const double h = dt.count();
  if (!std::isfinite(h) || h <= 0.0 || h > config_.max_time_step.count())
    return fault_output(CraneFault::kTimeStepInvalid, false);
  const Eigen::Matrix<double, 3, 2>& gains = gains_.advance(dt);

  CraneOutput out;
  out.status.gains_blending = gains_.blending();
  if (!enabled_) {
    const bool moving =
        ramp_to_zero(last_output_, config_.stop_deceleration_mps2.cwiseMax(config_.max_acceleration_mps2), h);
    if (!moving) reset_state();
    out.velocity_world_mps = last_output_;
    out.status.state = moving ? CraneState::kStopping : CraneState::kDisabled;
    out.status.acceleration_limited = moving;
    return out;
  }
  if (latched_fault_ != CraneFault::kNone) return fault_output(latched_fault_, true);

  if (!input.force_on_robot_world_n.allFinite()) return fault_output(CraneFault::kForceNotFinite, true);
  if (input.force_on_robot_world_n.norm() > config_.max_plausible_force_n)
    return fault_output(CraneFault::kForceImplausible, true);
  if (!input.robot_velocity_world_mps.allFinite() ||
      (input.rope_offset_world_m && !input.rope_offset_world_m->allFinite()))
    return fault_output(CraneFault::kInputInvalid, true);
  if (!is_fresh(input.force_age, config_.force_timeout)) return fault_output(CraneFault::kForceStale, false);

  // The force the robot applies to the load is the reaction to what the wrist measures.
  const Eigen::Vector3d interaction_n = -input.force_on_robot_world_n;
  filtered_force_ += low_pass_alpha(config_.force_filter_cutoff_hz, h) * (interaction_n - filtered_force_);

  const Eigen::Vector3d previous_admittance = admittance_velocity_;
  Eigen::Vector3d feedforward = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (!config_.selected_axes[static_cast<std::size_t>(i)]) {
      admittance_velocity_[i] = 0.0;
      continue;
    }
    const double force = apply_deadband(filtered_force_[i], config_.deadband_n[i]);
    out.force_applied_n[i] = force;
    const AxisDiscretisation& d = discretisation_[static_cast<std::size_t>(i)].get(gains(i, 0), gains(i, 1), 0.0, h);
    // With K = 0 the position row is unused: u(k+1) = phi(1,1) u(k) + gamma(1) f, the exact
    // first-order response with time constant M / D.
    admittance_velocity_[i] = d.phi(1, 1) * previous_admittance[i] + d.gamma[1] * force;
    feedforward[i] = config_.robot_velocity_feedforward * input.robot_velocity_world_mps[i];
    if (i < 2 && input.rope_offset_world_m)
      feedforward[i] += config_.rope_offset_gain_per_s * (*input.rope_offset_world_m)[i];
  }

  Eigen::Vector3d command = admittance_velocity_ + feedforward;
  // Bridge, trolley and hoist are independent drives: each is limited on its own, so that the slow
  // hoist does not hold the horizontal axes back (which would leave the rope trailing).
  out.status.velocity_limited = clamp_per_axis(command, config_.max_speed_mps);
  out.status.acceleration_limited = clamp_rate_per_axis(last_output_, command, config_.max_acceleration_mps2, h);
  if (out.status.velocity_limited || out.status.acceleration_limited) {
    // Back-calculation: the admittance state holds only what the crane is actually commanded.
    for (int i = 0; i < 3; ++i)
      if (config_.selected_axes[static_cast<std::size_t>(i)]) admittance_velocity_[i] = command[i] - feedforward[i];
  }
  last_output_ = command;
  out.velocity_world_mps = command;
  out.status.state = CraneState::kActive;
  return out;
}

}  // namespace rigger::control
