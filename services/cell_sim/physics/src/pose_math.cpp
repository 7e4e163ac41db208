#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {

Eigen::Isometry3d pose_from_position_rpy(const Eigen::Vector3d& position_m,
                                         const Eigen::Vector3d& rpy_rad) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = position_m;
  return pose;
}

Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& rotation) {
  // AngleAxis picks an angle in [0, pi]; its axis is arbitrary at zero angle, so scale by angle.
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.axis() * angle_axis.angle();
}

Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& rotation_vector_rad) {
  const double angle = rotation_vector_rad.norm();
  if (angle < 1e-12) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, rotation_vector_rad / angle).toRotationMatrix();
}

Eigen::Vector3d rotation_error(const Eigen::Matrix3d& desired, const Eigen::Matrix3d& actual) {
  return rotation_vector(desired * actual.transpose());
}

Eigen::Matrix<double, 6, 1> pose_error(const Eigen::Isometry3d& desired,
                                       const Eigen::Isometry3d& actual) {
  Eigen::Matrix<double, 6, 1> error;
  error.head<3>() = desired.translation() - actual.translation();
  error.tail<3>() = rotation_error(desired.linear(), actual.linear());
  return error;
}

}  // namespace rigger::sim
