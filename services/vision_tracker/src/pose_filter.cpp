#include "pose_filter.hpp"

#include <cmath>

namespace rigger::vision {

Eigen::Vector3d log_rotation(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d exp_rotation(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-15) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

PoseFilter::PoseFilter(const FilterSettings& settings) : settings_(settings) {}

void PoseFilter::reset() {
  initialised_ = false;
  linear_velocity_.setZero();
  angular_velocity_.setZero();
}

void PoseFilter::restart(const Eigen::Isometry3d& measured, Stamp stamp) {
  initialised_ = true;
  pose_ = measured;
  stamp_ = stamp;
  linear_velocity_.setZero();
  angular_velocity_.setZero();
}

FilterUpdate PoseFilter::update(const Eigen::Isometry3d& measured, Stamp stamp) {
  if (!measured.matrix().allFinite()) {
    return FilterUpdate::kRejected;
  }
  if (!settings_.enabled || !initialised_) {
    restart(measured, stamp);
    return FilterUpdate::kRestarted;
  }
  if (stamp <= stamp_) {
    return FilterUpdate::kRejected;
  }
  const auto gap = stamp - stamp_;
  if (gap > settings_.max_prediction) {
    restart(measured, stamp);
    return FilterUpdate::kRestarted;
  }
  const double dt = std::chrono::duration<double>(gap).count();
  // Predict across the gap at constant velocity, then correct with a share of the innovation.
  const Eigen::Vector3d predicted_position = pose_.translation() + linear_velocity_ * dt;
  const Eigen::Matrix3d predicted_rotation = exp_rotation(angular_velocity_ * dt) * pose_.linear();
  const Eigen::Vector3d position_innovation = measured.translation() - predicted_position;
  const Eigen::Vector3d rotation_innovation = log_rotation(measured.linear() * predicted_rotation.transpose());
  if (position_innovation.norm() > settings_.reset_distance_m ||
      rotation_innovation.norm() > settings_.reset_angle_deg * M_PI / 180.0) {
    restart(measured, stamp);
    return FilterUpdate::kRestarted;
  }
  pose_.translation() = predicted_position + settings_.position_gain * position_innovation;
  pose_.linear() = exp_rotation(settings_.position_gain * rotation_innovation) * predicted_rotation;
  linear_velocity_ += (settings_.velocity_gain / dt) * position_innovation;
  angular_velocity_ += (settings_.velocity_gain / dt) * rotation_innovation;
  stamp_ = stamp;
  return FilterUpdate::kFiltered;
}

}  // namespace rigger::vision
