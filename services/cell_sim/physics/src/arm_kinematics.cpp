#include "arm_kinematics.hpp"

#include <algorithm>
#include <vector>

#include "rigger/sim/pose_math.hpp"
#include "rigger/sim/resolved_rate.hpp"

namespace rigger::sim::detail {

ArmKinematics::ArmKinematics(const mjModel& model, const CellModelIndex& index)
    : model_(&model),
      index_(index),
      scratch_(mj_makeData(&model)),
      jacobian_linear_(static_cast<std::size_t>(3 * model.nv)),
      jacobian_angular_(static_cast<std::size_t>(3 * model.nv)) {
  if (!scratch_) {
    throw PhysicsModelError("MuJoCo could not allocate scratch data for the arm kinematics");
  }
  mj_kinematics(model_, scratch_.get());
  const int base = index_.robot_base_body;
  pose_world_base_ = to_isometry(scratch_->xpos + 3 * base, scratch_->xmat + 9 * base);
}

void ArmKinematics::set_configuration(const JointVector& q_rad) const {
  for (int j = 0; j < kArmJointCount; ++j) {
    scratch_->qpos[index_.arm[static_cast<std::size_t>(j)].qpos] = q_rad[j];
  }
  // Kinematics for the poses, comPos for the Jacobian (it needs cdof and subtree centres).
  mj_kinematics(model_, scratch_.get());
  mj_comPos(model_, scratch_.get());
}

Eigen::Isometry3d ArmKinematics::pose_base_tool(const JointVector& q_rad) const {
  set_configuration(q_rad);
  const int site = index_.tool_site;
  return pose_world_base_.inverse() *
         to_isometry(scratch_->site_xpos + 3 * site, scratch_->site_xmat + 9 * site);
}

void ArmKinematics::evaluate(const JointVector& q_rad, Eigen::Isometry3d& pose_base_tool,
                             Jacobian6x7& jacobian_base_tool) const {
  set_configuration(q_rad);
  const int site = index_.tool_site;
  const Eigen::Isometry3d pose_base_world = pose_world_base_.inverse();
  pose_base_tool =
      pose_base_world * to_isometry(scratch_->site_xpos + 3 * site, scratch_->site_xmat + 9 * site);

  const int nv = model_->nv;
  std::vector<mjtNum>& linear = jacobian_linear_;
  std::vector<mjtNum>& angular = jacobian_angular_;
  mj_jacSite(model_, scratch_.get(), linear.data(), angular.data(), site);
  const Eigen::Matrix3d rotation_base_world = pose_base_world.linear();
  for (int j = 0; j < kArmJointCount; ++j) {
    const int dof = index_.arm[static_cast<std::size_t>(j)].dof;
    const Eigen::Vector3d linear_world(linear[static_cast<std::size_t>(dof)],
                                       linear[static_cast<std::size_t>(nv + dof)],
                                       linear[static_cast<std::size_t>(2 * nv + dof)]);
    const Eigen::Vector3d angular_world(angular[static_cast<std::size_t>(dof)],
                                        angular[static_cast<std::size_t>(nv + dof)],
                                        angular[static_cast<std::size_t>(2 * nv + dof)]);
    jacobian_base_tool.block<3, 1>(0, j) = rotation_base_world * linear_world;
    jacobian_base_tool.block<3, 1>(3, j) = rotation_base_world * angular_world;
  }
}

IkResult ArmKinematics::solve(const Eigen::Isometry3d& goal_base_tool, const JointVector& seed,
                              const JointVector& q_min, const JointVector& q_max,
                              const IkOptions& options) const {
  IkResult result;
  JointVector q = seed.cwiseMax(q_min).cwiseMin(q_max);
  Eigen::Isometry3d pose;
  Jacobian6x7 jacobian;
  for (int iteration = 0; iteration <= options.max_iterations; ++iteration) {
    evaluate(q, pose, jacobian);
    const Vector6d error = pose_error(goal_base_tool, pose);
    result.position_error_m = error.head<3>().norm();
    result.orientation_error_rad = error.tail<3>().norm();
    result.iterations = iteration;
    result.position_rad = q;
    if (result.position_error_m < options.position_tolerance_m &&
        result.orientation_error_rad < options.orientation_tolerance_rad) {
      result.converged = true;
      return result;
    }
    JointVector step = damped_least_squares(jacobian, error, options.damping);
    const double largest = step.cwiseAbs().maxCoeff();
    if (largest > options.max_step_rad) {
      step *= options.max_step_rad / largest;
    }
    q = (q + step).cwiseMax(q_min).cwiseMin(q_max);
  }
  return result;
}

}  // namespace rigger::sim::detail
