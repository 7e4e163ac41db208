#include "rigger/dds/conversions.hpp"

namespace rigger::dds {

rigger_geometry_Time to_wire(WallTime t) {
  const std::int64_t ns = to_unix_ns(t);
  std::int64_t sec = ns / 1'000'000'000;
  std::int64_t nsec = ns % 1'000'000'000;
  if (nsec < 0) {  // builtin_interfaces/Time: nanosec is always in [0, 1e9)
    nsec += 1'000'000'000;
    sec -= 1;
  }
  return rigger_geometry_Time{static_cast<int32_t>(sec), static_cast<uint32_t>(nsec)};
}

WallTime to_domain(const rigger_geometry_Time& t) {
  return from_unix_ns(static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec);
}

rigger_geometry_Time wire_now() { return to_wire(std::chrono::system_clock::now()); }

rigger_geometry_Vector3 to_wire_vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
rigger_geometry_Point to_wire_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
rigger_geometry_Quaternion to_wire(const Eigen::Quaterniond& q) { return {q.x(), q.y(), q.z(), q.w()}; }

rigger_geometry_Pose to_wire(const Eigen::Isometry3d& pose) {
  return {to_wire_point(pose.translation()), to_wire(Eigen::Quaterniond(pose.rotation()))};
}

rigger_geometry_Twist to_wire_twist(const Vector6d& twist) {
  return {to_wire_vector(twist.head<3>()), to_wire_vector(twist.tail<3>())};
}

rigger_geometry_Wrench to_wire_wrench(const Vector6d& wrench) {
  return {to_wire_vector(wrench.head<3>()), to_wire_vector(wrench.tail<3>())};
}

Eigen::Vector3d to_domain(const rigger_geometry_Vector3& v) { return {v.x, v.y, v.z}; }
Eigen::Vector3d to_domain(const rigger_geometry_Point& p) { return {p.x, p.y, p.z}; }
Eigen::Quaterniond to_domain(const rigger_geometry_Quaternion& q) { return {q.w, q.x, q.y, q.z}; }

Eigen::Isometry3d to_domain(const rigger_geometry_Pose& pose) {
  Eigen::Quaterniond q = to_domain(pose.orientation);
  if (q.norm() < 1e-12) q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = to_domain(pose.position);
  return out;
}

Vector6d to_domain(const rigger_geometry_Twist& twist) {
  Vector6d out;
  out << to_domain(twist.linear), to_domain(twist.angular);
  return out;
}

Vector6d to_domain(const rigger_geometry_Wrench& wrench) {
  Vector6d out;
  out << to_domain(wrench.force), to_domain(wrench.torque);
  return out;
}

Eigen::Matrix<double, 6, 6> covariance_to_domain(const double (&cov)[36]) {
  return Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(cov);
}

void covariance_to_wire(const Eigen::Matrix<double, 6, 6>& cov, double (&out)[36]) {
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> wire(out);
  wire = cov;
}

}  // namespace rigger::dds
