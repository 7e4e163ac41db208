#pragma once
// Small rigid-body helpers shared by the physics (pure Eigen, no state).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigger::sim {

/// Pose from a position (m) and roll, pitch, yaw (rad), with R = Rz(yaw) Ry(pitch) Rx(roll): the
/// convention of the cell JSON.
Eigen::Isometry3d pose_from_position_rpy(const Eigen::Vector3d& position_m,
                                         const Eigen::Vector3d& rpy_rad);

/// Rotation vector (axis * angle, rad) that turns `actual` into `desired`, in the frame both are
/// expressed in: log(desired * actual^T).  Angle in [0, pi].
Eigen::Vector3d rotation_error(const Eigen::Matrix3d& desired, const Eigen::Matrix3d& actual);

/// Stacked (position error m, rotation error rad) of `desired` relative to `actual`, both in the
/// same frame.
Eigen::Matrix<double, 6, 1> pose_error(const Eigen::Isometry3d& desired,
                                       const Eigen::Isometry3d& actual);

/// Rotation vector of a rotation matrix (axis * angle, angle in [0, pi]).
Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& rotation);

/// Rotation matrix of a rotation vector (axis * angle).
Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& rotation_vector_rad);

}  // namespace rigger::sim
