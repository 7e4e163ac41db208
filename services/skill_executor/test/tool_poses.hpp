#pragma once
// Tool poses for the gripper skills' tests (AttachRobotToLoad, Release, Pick, Place).
#include <cmath>

#include <Eigen/Geometry>

namespace rigger::skill_executor {

/// A tool pose in the robot base frame: position (m), tool z along +x of the base (as grasp_side).
inline Eigen::Isometry3d tool_facing_x(double x, double y, double z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

/// A tool pose in the robot base frame with the tool z pointing down (a pick from above).
inline Eigen::Isometry3d tool_down(double x, double y, double z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

}  // namespace rigger::skill_executor
