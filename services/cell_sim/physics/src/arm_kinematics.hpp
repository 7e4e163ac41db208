#pragma once
// Internal: forward kinematics, Jacobian and inverse kinematics of the arm on MuJoCo's model,
// evaluated on a private scratch mjData so that queries never disturb the simulation.

#include <vector>

#include "cell_model.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::sim::detail {

using Jacobian6x7 = Eigen::Matrix<double, 6, kArmJointCount>;

struct IkOptions {
  int max_iterations = 200;
  double position_tolerance_m = 1e-4;
  double orientation_tolerance_rad = 1e-3;
  double damping = 0.02;
  double max_step_rad = 0.2;
};

/// Kinematics of the arm in its base frame.  Holds a pointer to the model (which must outlive
/// it) and its own mjData.  Not thread-safe, including const queries (they reuse the scratch).
class ArmKinematics {
 public:
  ArmKinematics(const mjModel& model, const CellModelIndex& index);

  /// Tool pose in the base frame at q.
  [[nodiscard]] Eigen::Isometry3d pose_base_tool(const JointVector& q_rad) const;

  /// Tool pose and the Jacobian of the tool point (rows: linear, then angular; base frame) at q.
  void evaluate(const JointVector& q_rad, Eigen::Isometry3d& pose_base_tool,
                Jacobian6x7& jacobian_base_tool) const;

  /// Damped least squares from `seed`, clamped to [q_min, q_max].  Never throws.
  [[nodiscard]] IkResult solve(const Eigen::Isometry3d& goal_base_tool, const JointVector& seed,
                               const JointVector& q_min, const JointVector& q_max,
                               const IkOptions& options = {}) const;

  [[nodiscard]] const Eigen::Isometry3d& pose_world_base() const { return pose_world_base_; }

 private:
  void set_configuration(const JointVector& q_rad) const;

  const mjModel* model_;
  CellModelIndex index_;
  DataPtr scratch_;
  mutable std::vector<mjtNum> jacobian_linear_;  // 3 x nv, row-major (MuJoCo's layout)
  mutable std::vector<mjtNum> jacobian_angular_;
  Eigen::Isometry3d pose_world_base_ = Eigen::Isometry3d::Identity();
};

}  // namespace rigger::sim::detail
