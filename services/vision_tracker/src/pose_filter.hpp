#pragma once
/// @file
/// Temporal filter of an object's pose: a constant-velocity alpha-beta filter on SE(3). It smooths
/// measurement noise without lagging a steadily moving object, and only ever reports the pose at
/// the stamp of the measurement it last took in: it never extrapolates into the future, and it
/// predicts across a gap between measurements only up to a configured length.

#include "tracker_config.hpp"

#include <Eigen/Geometry>

namespace rigger::vision {

/// What an update did.
enum class FilterUpdate {
  /// Folded into the running estimate.
  kFiltered,
  /// (Re)started from the measurement: first one, gap too long, or innovation too large.
  kRestarted,
  /// Stamp not after the previous measurement's, or a non-finite pose: ignored, nothing changed.
  kRejected,
};

/// Not thread safe.
class PoseFilter {
 public:
  explicit PoseFilter(const FilterSettings& settings);

  /// Takes in a measured pose (any fixed frame; the output is in the same frame) taken at stamp.
  FilterUpdate update(const Eigen::Isometry3d& measured, Stamp stamp);

  /// Forgets everything.
  void reset();

  bool initialised() const { return initialised_; }
  /// The filtered pose at stamp(). Meaningful only once initialised().
  const Eigen::Isometry3d& pose() const { return pose_; }
  /// The stamp of the last measurement taken in.
  Stamp stamp() const { return stamp_; }
  /// Estimated linear (m/s) and angular (rad/s, fixed-frame axes) velocity.
  const Eigen::Vector3d& linear_velocity() const { return linear_velocity_; }
  const Eigen::Vector3d& angular_velocity() const { return angular_velocity_; }

 private:
  void restart(const Eigen::Isometry3d& measured, Stamp stamp);

  FilterSettings settings_;
  bool initialised_ = false;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d linear_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_ = Eigen::Vector3d::Zero();
  Stamp stamp_{};
};

/// The rotation vector (axis times angle, radians) of r.
Eigen::Vector3d log_rotation(const Eigen::Matrix3d& r);
/// The rotation of a rotation vector.
Eigen::Matrix3d exp_rotation(const Eigen::Vector3d& rotation_vector);

}  // namespace rigger::vision
