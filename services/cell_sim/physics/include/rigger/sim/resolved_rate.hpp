#pragma once
// Resolved-rate motion control: joint velocities for a Cartesian twist, by damped least squares
// on the manipulator Jacobian, with joint position and speed limits enforced.  Pure Eigen.

#include <Eigen/Core>

namespace rigger::sim {

/// Joint limits for the solver; every vector has one entry per joint.
struct ResolvedRateLimits {
  Eigen::VectorXd position_min_rad;
  Eigen::VectorXd position_max_rad;
  Eigen::VectorXd speed_max_rad_per_s;
  /// Used for braking distances: a joint never moves towards a limit faster than it can stop.
  Eigen::VectorXd accel_max_rad_per_s2;
};

struct ResolvedRateParams {
  /// Damping starts when the smallest singular value of the Jacobian drops below this.
  double singular_value_threshold = 0.04;
  /// Damping factor lambda at a singularity (same units as the Jacobian).
  double max_damping = 0.04;
  /// Inside this fraction of its range from a limit, a joint is pushed back in the null space.
  double limit_margin_fraction = 0.08;
  /// Null-space push gain (1/s) per radian inside the margin.
  double limit_avoidance_gain = 2.0;
};

struct ResolvedRateResult {
  Eigen::VectorXd joint_velocity_rad_per_s;
  /// Uniform factor (0..1] applied to respect the speed limits; 1 when none was hit.
  double speed_scale = 1.0;
  /// Joints whose velocity a position limit clamped (they no longer serve the task).
  int joints_limited = 0;
  double min_singular_value = 0.0;
  bool damped = false;
};

/// Joint velocities that realise `twist` (6: linear then angular, in the Jacobian's frame) as
/// closely as the limits allow.  Joints that would run into a position limit are clamped and the
/// task is re-solved with the others; then all velocities are scaled by one factor to respect the
/// speed limits (the direction of motion is kept).  Sizes: jacobian 6 x n, q and limits n.
/// Never throws; a size mismatch returns zero velocity.
ResolvedRateResult solve_resolved_rate(const Eigen::MatrixXd& jacobian,
                                       const Eigen::Matrix<double, 6, 1>& twist,
                                       const Eigen::VectorXd& q_rad,
                                       const ResolvedRateLimits& limits,
                                       const ResolvedRateParams& params = {});

/// Damped least-squares step towards `error` (6) with damping lambda: J^T (J J^T + lambda^2 I)^-1
/// e.
Eigen::VectorXd damped_least_squares(const Eigen::MatrixXd& jacobian,
                                     const Eigen::Matrix<double, 6, 1>& error, double lambda);

}  // namespace rigger::sim
