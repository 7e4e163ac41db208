#pragma once
// What the RobotAdmittance tests share (robot_admittance_test.cpp: the law's dynamics;
// robot_admittance_inputs_test.cpp: its inputs, faults, frames, modes and references): the step, the bare
// law and wrench samples.
#include <limits>

#include "robot_admittance.hpp"

namespace rigger::control::admittance_test {

constexpr double kH = 0.002;  // 500 Hz
inline const Seconds kDt{kH};
inline const Eigen::Quaterniond kUpright = Eigen::Quaterniond::Identity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// No deadband, no filter, limits out of the way, gains applied at once: the bare law.
inline RobotAdmittanceConfig bare_config() {
  RobotAdmittanceConfig c;
  c.deadband.setZero();
  c.force_filter_cutoff_hz = 0.0;
  c.reference_filter_cutoff_hz = 0.0;
  c.limits.max_velocity.setConstant(100.0);
  c.limits.max_linear_speed_mps = 0.0;
  c.limits.max_angular_speed_radps = 0.0;
  c.limits.max_acceleration.setConstant(1e6);
  c.gain_transition_time = Seconds(0.0);
  return c;
}

inline WrenchSample sample(const Vector6d& wrench, double age_s = 0.001) {
  return WrenchSample{Wrench::from_stacked(wrench), Seconds(age_s)};
}

inline Vector6d axis_value(int axis, double value) {
  Vector6d v = Vector6d::Zero();
  v[axis] = value;
  return v;
}

inline RobotAdmittance active_law(const RobotAdmittanceConfig& config) {
  RobotAdmittance law(config);
  law.set_mode(AdmittanceMode::kRobot);
  return law;
}

}  // namespace rigger::control::admittance_test
