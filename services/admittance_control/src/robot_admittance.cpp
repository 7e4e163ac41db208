#include "robot_admittance.hpp"

#include <cmath>
#include <utility>

#include "config_checks.hpp"
#include "rigger/base/config.hpp"

namespace rigger::control {
namespace {

// Quaternions further than this from unit norm are refused instead of silently normalised: they
// point at a broken producer, not at rounding.
constexpr double kQuaternionNormTolerance = 1e-3;

bool quaternion_usable(const Eigen::Quaterniond& q) {
  return q.coeffs().allFinite() && std::abs(q.norm() - 1.0) <= kQuaternionNormTolerance;
}

Eigen::Matrix<double, 6, 3> to_matrix(const AdmittanceGains& gains) {
  Eigen::Matrix<double, 6, 3> m;
  m << gains.mass, gains.damping, gains.stiffness;
  return m;
}

AdmittanceGains to_gains(const Eigen::Matrix<double, 6, 3>& m) {
  AdmittanceGains g;
  g.mass = m.col(0);
  g.damping = m.col(1);
  g.stiffness = m.col(2);
  return g;
}

}  // namespace

std::string_view to_string(AdmittanceMode mode) {
  switch (mode) {
    case AdmittanceMode::kOff: return "OFF";
    case AdmittanceMode::kRobot: return "ROBOT";
    case AdmittanceMode::kRobotAndCrane: return "ROBOT_AND_CRANE";
  }
  return "?";
}

std::string_view to_string(ReferenceSource source) {
  switch (source) {
    case ReferenceSource::kNone: return "NONE";
    case ReferenceSource::kJoystick: return "JOYSTICK";
    case ReferenceSource::kVisualServo: return "VISUAL_SERVO";
  }
  return "?";
}

std::string_view to_string(ControlFrame frame) { return frame == ControlFrame::kBase ? "base" : "tool"; }

std::optional<AdmittanceMode> admittance_mode_from_string(std::string_view text) {
  for (auto m : {AdmittanceMode::kOff, AdmittanceMode::kRobot, AdmittanceMode::kRobotAndCrane})
    if (to_string(m) == text) return m;
  return std::nullopt;
}

std::optional<ReferenceSource> reference_source_from_string(std::string_view text) {
  for (auto s : {ReferenceSource::kNone, ReferenceSource::kJoystick, ReferenceSource::kVisualServo})
    if (to_string(s) == text) return s;
  return std::nullopt;
}

std::optional<ControlFrame> control_frame_from_string(std::string_view text) {
  for (auto f : {ControlFrame::kBase, ControlFrame::kTool})
    if (to_string(f) == text) return f;
  return std::nullopt;
}

std::string_view to_string(AdmittanceState state) {
  switch (state) {
    case AdmittanceState::kOff: return "OFF";
    case AdmittanceState::kStopping: return "STOPPING";
    case AdmittanceState::kActive: return "ACTIVE";
    case AdmittanceState::kFault: return "FAULT";
  }
  return "?";
}

std::string_view to_string(AdmittanceFault fault) {
  switch (fault) {
    case AdmittanceFault::kNone: return "NONE";
    case AdmittanceFault::kWrenchStale: return "WRENCH_STALE";
    case AdmittanceFault::kWrenchNotFinite: return "WRENCH_NOT_FINITE";
    case AdmittanceFault::kWrenchImplausible: return "WRENCH_IMPLAUSIBLE";
    case AdmittanceFault::kOrientationInvalid: return "ORIENTATION_INVALID";
    case AdmittanceFault::kReferenceInvalid: return "REFERENCE_INVALID";
    case AdmittanceFault::kTimeStepInvalid: return "TIME_STEP_INVALID";
  }
  return "?";
}

std::string_view to_string(ReferenceStatus status) {
  switch (status) {
    case ReferenceStatus::kNotSelected: return "NOT_SELECTED";
    case ReferenceStatus::kApplied: return "APPLIED";
    case ReferenceStatus::kStale: return "STALE";
    case ReferenceStatus::kOtherSource: return "OTHER_SOURCE";
  }
  return "?";
}

std::optional<ConfigProblem> find_problem(const AdmittanceGains& gains) {
  if (auto p = check_axes(gains.mass, "/mass", Bound::kPositive, "kg or kg m^2")) return p;
  if (auto p = check_axes(gains.damping, "/damping", Bound::kPositive, "N s/m or N m s/rad")) return p;
  return check_axes(gains.stiffness, "/stiffness", Bound::kNonNegative, "N/m or N m/rad");
}

std::optional<ConfigProblem> find_problem(const MotionLimits& limits) {
  if (auto p = check_axes(limits.max_velocity, "/max_velocity", Bound::kNonNegative, "m/s or rad/s")) return p;
  if (auto p = check_scalar(limits.max_linear_speed_mps, "/max_linear_speed_mps", Bound::kNonNegative, "m/s"))
    return p;
  if (auto p = check_scalar(limits.max_angular_speed_radps, "/max_angular_speed_radps", Bound::kNonNegative, "rad/s"))
    return p;
  if (auto p = check_axes(limits.max_acceleration, "/max_acceleration", Bound::kPositive, "m/s^2 or rad/s^2")) return p;
  return check_axes(limits.stop_deceleration, "/stop_deceleration", Bound::kPositive, "m/s^2 or rad/s^2");
}

std::optional<ConfigProblem> find_problem(const RobotAdmittanceConfig& c) {
  if (auto p = prefixed(find_problem(c.gains), "/gains")) return p;
  if (auto p = prefixed(find_problem(c.limits), "/limits")) return p;
  if (auto p = check_axes(c.deadband, "/deadband", Bound::kNonNegative, "N or N m")) return p;
  if (auto p = check_scalar(c.force_filter_cutoff_hz, "/force_filter_cutoff_hz", Bound::kNonNegative, "Hz")) return p;
  if (auto p = check_scalar(c.reference_filter_cutoff_hz, "/reference_filter_cutoff_hz", Bound::kNonNegative, "Hz"))
    return p;
  if (auto p = check_scalar(c.tool.mass_kg, "/tool/mass_kg", Bound::kNonNegative, "kg")) return p;
  if (auto p = check_finite(c.tool.center_of_mass_m, "/tool/center_of_mass_m", "m")) return p;
  if (auto p = check_finite(c.sensor_bias.force_n, "/sensor_bias/force_n", "N")) return p;
  if (auto p = check_finite(c.sensor_bias.torque_nm, "/sensor_bias/torque_nm", "N m")) return p;
  if (auto p = check_finite(c.tcp_in_sensor_m, "/tcp_in_sensor_m", "m")) return p;
  if (auto p = check_finite(c.gravity_base_mps2, "/gravity_base_mps2", "m/s^2")) return p;
  if (auto p = check_scalar(c.wrench_timeout.count(), "/wrench_timeout_s", Bound::kPositive, "s")) return p;
  if (auto p = check_scalar(c.reference_timeout.count(), "/reference_timeout_s", Bound::kPositive, "s")) return p;
  if (auto p = check_scalar(c.max_time_step.count(), "/max_time_step_s", Bound::kPositive, "s")) return p;
  if (auto p = check_scalar(c.max_plausible_force_n, "/max_plausible_force_n", Bound::kPositive, "N")) return p;
  if (auto p = check_scalar(c.max_plausible_torque_nm, "/max_plausible_torque_nm", Bound::kPositive, "N m")) return p;
  return check_scalar(c.gain_transition_time.count(), "/gain_transition_time_s", Bound::kNonNegative, "s");
}

Wrench compensate_tool_weight(const Wrench& measured_sensor, const Eigen::Matrix3d& R_base_sensor,
                              const ToolModel& tool, const Eigen::Vector3d& gravity_base_mps2,
                              const Wrench& sensor_bias) {
  // The sensor carries the tool: it reads the tool's weight plus the contact wrench. The weight is
  // fixed in the base frame, so it moves in the sensor frame as the tool turns.
  const Eigen::Vector3d weight_sensor_n = R_base_sensor.transpose() * (tool.mass_kg * gravity_base_mps2);
  Wrench out;
  out.force_n = measured_sensor.force_n - sensor_bias.force_n - weight_sensor_n;
  out.torque_nm = measured_sensor.torque_nm - sensor_bias.torque_nm - tool.center_of_mass_m.cross(weight_sensor_n);
  return out;
}

RobotAdmittance::RobotAdmittance(RobotAdmittanceConfig config)
    : config_(std::move(config)), gains_(to_matrix(config_.gains)) {
  if (auto p = find_problem(config_)) throw ConfigError("RobotAdmittanceConfig", p->pointer, p->problem);
}

void RobotAdmittance::set_mode(AdmittanceMode mode) {
  latched_fault_ = AdmittanceFault::kNone;
  if (mode_ == AdmittanceMode::kOff && mode != AdmittanceMode::kOff) {
    // Restart from whatever is still being commanded (zero, or the remainder of a stop ramp): the
    // deviation state absorbs it, so the output continues without a jump.
    deviation_.setZero();
    deviation_rate_ = last_output_;
    filtered_wrench_.setZero();
    filtered_reference_.setZero();
  }
  mode_ = mode;
}

RequestResult RobotAdmittance::set_gains(const AdmittanceGains& gains) {
  if (auto p = find_problem(gains)) return {false, "gains" + p->pointer + ": " + p->problem};
  if (gains == target_gains()) return {};
  for (int i = 0; i < 6; ++i)
    if (gains_.current()(i, 2) == 0.0) deviation_[i] = 0.0;
  gains_.set_target(to_matrix(gains), config_.gain_transition_time);
  return {};
}

AdmittanceGains RobotAdmittance::current_gains() const { return to_gains(gains_.current()); }

AdmittanceGains RobotAdmittance::target_gains() const { return to_gains(gains_.target()); }

RequestResult RobotAdmittance::set_limits(const MotionLimits& limits) {
  if (auto p = find_problem(limits)) return {false, "limits" + p->pointer + ": " + p->problem};
  config_.limits = limits;
  return {};
}

void RobotAdmittance::set_selected_axes(const std::array<bool, 6>& selected) { config_.selected_axes = selected; }

void RobotAdmittance::set_reference_source(ReferenceSource source) { reference_source_ = source; }

void RobotAdmittance::reset_anchor() { deviation_.setZero(); }

void RobotAdmittance::reset_state() {
  deviation_.setZero();
  deviation_rate_.setZero();
  filtered_wrench_.setZero();
  filtered_reference_.setZero();
  last_output_.setZero();
}

AdmittanceOutput RobotAdmittance::fault_output(AdmittanceFault fault, bool latch) {
  // A fault commands zero at once (the robot controller's own stop takes over) and forgets the
  // motion state, so that recovery starts from rest instead of resuming an old velocity.
  if (latch) latched_fault_ = fault;
  reset_state();
  AdmittanceOutput out;
  out.frame = config_.frame;
  out.status.state = AdmittanceState::kFault;
  out.status.fault = fault;
  out.status.fault_latched = latch;
  out.status.gains_blending = gains_.blending();
  return out;
}

AdmittanceOutput RobotAdmittance::stopping_output(double dt_s) {
  AdmittanceOutput out;
  out.frame = config_.frame;
  out.status.gains_blending = gains_.blending();
  Eigen::Vector3d linear = last_output_.head<3>();
  Eigen::Vector3d angular = last_output_.tail<3>();
  const Vector6d rate = config_.limits.stop_deceleration.cwiseMax(config_.limits.max_acceleration);
  const bool linear_moving = ramp_to_zero(linear, rate.head<3>(), dt_s);
  const bool angular_moving = ramp_to_zero(angular, rate.tail<3>(), dt_s);
  last_output_ << linear, angular;
  out.twist = Twist::from_stacked(last_output_);
  if (!linear_moving && !angular_moving) {
    reset_state();
    out.status.state = AdmittanceState::kOff;
  } else {
    out.status.state = AdmittanceState::kStopping;
    out.status.acceleration_limited = true;
  }
  return out;
}

AdmittanceOutput RobotAdmittance::step(Seconds dt, const WrenchSample& wrench,
                                       const Eigen::Quaterniond& orientation_base_sensor,
                                       const ReferenceInput& reference) {
  const double h = dt.count();
  const bool step_valid = std::isfinite(h) && h > 0.0 && h <= config_.max_time_step.count();
  // OFF commands nothing: a late loop iteration (a busy machine) must not turn into a zero twist that
  // preempts the robot's own point-to-point motion. A ramp to zero still in progress goes on at the
  // longest valid step.
  if (mode_ == AdmittanceMode::kOff) {
    if (step_valid) gains_.advance(dt);
    return stopping_output(step_valid ? h : config_.max_time_step.count());
  }
  if (!step_valid) return fault_output(AdmittanceFault::kTimeStepInvalid, false);
  const Eigen::Matrix<double, 6, 3>& gains = gains_.advance(dt);
  if (latched_fault_ != AdmittanceFault::kNone) return fault_output(latched_fault_, true);

  // Input checks. Invalid numbers are a broken producer and latch; never read them as "no force".
  const Wrench& measured = wrench.wrench_sensor;
  if (!measured.all_finite()) return fault_output(AdmittanceFault::kWrenchNotFinite, true);
  if (measured.force_n.norm() > config_.max_plausible_force_n ||
      measured.torque_nm.norm() > config_.max_plausible_torque_nm)
    return fault_output(AdmittanceFault::kWrenchImplausible, true);
  if (!quaternion_usable(orientation_base_sensor)) return fault_output(AdmittanceFault::kOrientationInvalid, true);
  if (!is_fresh(wrench.age, config_.wrench_timeout)) return fault_output(AdmittanceFault::kWrenchStale, false);

  const Eigen::Matrix3d R_base_sensor = orientation_base_sensor.normalized().toRotationMatrix();

  AdmittanceOutput out;
  out.frame = config_.frame;
  out.status.state = AdmittanceState::kActive;
  out.status.gains_blending = gains_.blending();

  // Reference twist, in the control frame; a reference that is not applied fades out through the
  // same filter.
  Vector6d reference_control = Vector6d::Zero();
  if (reference_source_ == ReferenceSource::kNone) {
    out.status.reference = ReferenceStatus::kNotSelected;
  } else if (reference.source != reference_source_) {
    out.status.reference = ReferenceStatus::kOtherSource;
  } else if (!reference.twist.all_finite()) {
    return fault_output(AdmittanceFault::kReferenceInvalid, true);
  } else if (!is_fresh(reference.age, config_.reference_timeout)) {
    out.status.reference = ReferenceStatus::kStale;
  } else {
    Twist twist = reference.twist;
    if (reference.frame != config_.frame)
      twist = rotate(reference.frame == ControlFrame::kBase ? Eigen::Matrix3d(R_base_sensor.transpose()) : R_base_sensor,
                     twist);
    reference_control = twist.stacked();
    out.status.reference = ReferenceStatus::kApplied;
  }
  filtered_reference_ += low_pass_alpha(config_.reference_filter_cutoff_hz, h) * (reference_control - filtered_reference_);
  reference_control = filtered_reference_;

  // Contact wrench about the TCP: compensated in the sensor frame, then in the control frame.
  const Wrench compensated_sensor =
      compensate_tool_weight(measured, R_base_sensor, config_.tool, config_.gravity_base_mps2, config_.sensor_bias);
  const Wrench at_tcp_sensor = shift_wrench(compensated_sensor, config_.tcp_in_sensor_m);
  out.wrench_base = rotate(R_base_sensor, at_tcp_sensor);
  const Vector6d wrench_control =
      (config_.frame == ControlFrame::kBase ? out.wrench_base : at_tcp_sensor).stacked();

  filtered_wrench_ += low_pass_alpha(config_.force_filter_cutoff_hz, h) * (wrench_control - filtered_wrench_);
  Vector6d force = Vector6d::Zero();
  for (int i = 0; i < 6; ++i)
    if (config_.selected_axes[static_cast<std::size_t>(i)])
      force[i] = apply_deadband(filtered_wrench_[i], config_.deadband[i]);
  out.wrench_applied = Wrench::from_stacked(force);

  // Exact discretisation of M de/dt + D e + K x = f per axis.
  const Vector6d previous_rate = deviation_rate_;
  const Vector6d previous_deviation = deviation_;
  for (int i = 0; i < 6; ++i) {
    if (!config_.selected_axes[static_cast<std::size_t>(i)]) {
      deviation_[i] = 0.0;
      deviation_rate_[i] = 0.0;
      continue;
    }
    const AxisDiscretisation& d =
        discretisation_[static_cast<std::size_t>(i)].get(gains(i, 0), gains(i, 1), gains(i, 2), h);
    const Eigen::Vector2d state = d.phi * Eigen::Vector2d(deviation_[i], deviation_rate_[i]) + d.gamma * force[i];
    deviation_[i] = state[0];
    deviation_rate_[i] = state[1];
  }

  // Limits: velocity (direction kept), then acceleration relative to the last command. The
  // acceleration limit comes last so that nothing, not even a lowered velocity limit, makes the
  // command jump.
  Vector6d command = reference_control + deviation_rate_;
  Eigen::Vector3d linear = command.head<3>();
  Eigen::Vector3d angular = command.tail<3>();
  const MotionLimits& lim = config_.limits;
  const bool linear_clipped = limit_preserving_direction(linear, lim.max_velocity.head<3>(), lim.max_linear_speed_mps);
  const bool angular_clipped =
      limit_preserving_direction(angular, lim.max_velocity.tail<3>(), lim.max_angular_speed_radps);
  out.status.velocity_limited = linear_clipped || angular_clipped;
  const bool linear_rate_clipped = limit_rate(last_output_.head<3>(), linear, lim.max_acceleration.head<3>(), h);
  const bool angular_rate_clipped = limit_rate(last_output_.tail<3>(), angular, lim.max_acceleration.tail<3>(), h);
  out.status.acceleration_limited = linear_rate_clipped || angular_rate_clipped;
  command << linear, angular;

  if (out.status.velocity_limited || out.status.acceleration_limited) {
    // Anti-windup by back-calculation: the deviation state takes the motion actually commanded, so
    // the law neither stores unexecuted velocity nor jumps when the limit releases.
    for (int i = 0; i < 6; ++i) {
      if (!config_.selected_axes[static_cast<std::size_t>(i)]) continue;
      deviation_rate_[i] = command[i] - reference_control[i];
      deviation_[i] = previous_deviation[i] + 0.5 * h * (previous_rate[i] + deviation_rate_[i]);
    }
  }
  last_output_ = command;
  out.twist = Twist::from_stacked(command);
  return out;
}

}  // namespace rigger::control
