#include "control_types.hpp"

namespace rigger::control {

Vector6d Wrench::stacked() const {
  Vector6d out;
  out << force_n, torque_nm;
  return out;
}

Wrench Wrench::from_stacked(const Vector6d& values) {
  return Wrench{values.head<3>(), values.tail<3>()};
}

bool Wrench::all_finite() const { return force_n.allFinite() && torque_nm.allFinite(); }

Vector6d Twist::stacked() const {
  Vector6d out;
  out << linear_mps, angular_radps;
  return out;
}

Twist Twist::from_stacked(const Vector6d& values) { return Twist{values.head<3>(), values.tail<3>()}; }

bool Twist::all_finite() const { return linear_mps.allFinite() && angular_radps.allFinite(); }

Wrench rotate(const Eigen::Matrix3d& R_a_b, const Wrench& wrench_b) {
  return Wrench{R_a_b * wrench_b.force_n, R_a_b * wrench_b.torque_nm};
}

Twist rotate(const Eigen::Matrix3d& R_a_b, const Twist& twist_b) {
  return Twist{R_a_b * twist_b.linear_mps, R_a_b * twist_b.angular_radps};
}

Wrench shift_wrench(const Wrench& wrench_about_a, const Eigen::Vector3d& r_a_b_m) {
  return Wrench{wrench_about_a.force_n, wrench_about_a.torque_nm - r_a_b_m.cross(wrench_about_a.force_n)};
}

Twist shift_twist(const Twist& twist_at_a, const Eigen::Vector3d& r_a_b_m) {
  return Twist{twist_at_a.linear_mps + twist_at_a.angular_radps.cross(r_a_b_m), twist_at_a.angular_radps};
}

}  // namespace rigger::control
