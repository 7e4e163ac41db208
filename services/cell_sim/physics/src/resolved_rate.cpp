#include "rigger/sim/resolved_rate.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

namespace rigger::sim {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Tiny regularisation so that J J^T stays invertible when fewer than six joints are active;
// directions it amplifies lie in the null space of J^T and vanish again.
constexpr double kRegularisation = 1e-10;

struct DampedInverse {
  Eigen::MatrixXd pseudo_inverse;  // n x 6
  double min_singular_value = 0.0;
  bool damped = false;
};

DampedInverse damped_inverse(const Eigen::MatrixXd& jacobian, const ResolvedRateParams& params) {
  const Matrix6d jjt = jacobian * jacobian.transpose();
  // Singular values from the eigenvalues of J J^T (ascending): cheaper than an SVD at 1 kHz.
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(jjt, Eigen::EigenvaluesOnly);
  const Eigen::Index rank = std::min<Eigen::Index>(6, jacobian.cols());
  const double min_sigma_sq = std::max(0.0, eigen.eigenvalues()[6 - rank]);
  DampedInverse result;
  result.min_singular_value = std::sqrt(min_sigma_sq);
  double lambda_sq = 0.0;
  if (result.min_singular_value < params.singular_value_threshold) {
    // Nakamura-Hanafusa style: damping grows smoothly as the arm nears a singularity.
    const double ratio = result.min_singular_value / params.singular_value_threshold;
    lambda_sq = (1.0 - ratio * ratio) * params.max_damping * params.max_damping;
    result.damped = true;
  }
  const Matrix6d regularised = jjt + (lambda_sq + kRegularisation) * Matrix6d::Identity();
  result.pseudo_inverse = jacobian.transpose() * regularised.ldlt().solve(Matrix6d::Identity());
  return result;
}

}  // namespace

Eigen::VectorXd damped_least_squares(const Eigen::MatrixXd& jacobian,
                                     const Eigen::Matrix<double, 6, 1>& error, double lambda) {
  const Matrix6d regularised =
      jacobian * jacobian.transpose() + (lambda * lambda + kRegularisation) * Matrix6d::Identity();
  return jacobian.transpose() * regularised.ldlt().solve(error);
}

ResolvedRateResult solve_resolved_rate(const Eigen::MatrixXd& jacobian,
                                       const Eigen::Matrix<double, 6, 1>& twist,
                                       const Eigen::VectorXd& q_rad,
                                       const ResolvedRateLimits& limits,
                                       const ResolvedRateParams& params) {
  const Eigen::Index n = jacobian.cols();
  ResolvedRateResult result;
  result.joint_velocity_rad_per_s = Eigen::VectorXd::Zero(std::max<Eigen::Index>(n, 0));
  if (jacobian.rows() != 6 || q_rad.size() != n || limits.position_min_rad.size() != n ||
      limits.position_max_rad.size() != n || limits.speed_max_rad_per_s.size() != n ||
      limits.accel_max_rad_per_s2.size() != n || !twist.allFinite() || !q_rad.allFinite()) {
    return result;
  }

  // Velocity bounds from the position limits: never faster towards a limit than braking at the
  // acceleration limit allows, zero at (or beyond) the limit.
  Eigen::VectorXd upper(n);
  Eigen::VectorXd lower(n);
  Eigen::VectorXd avoidance = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double room_up = std::max(0.0, limits.position_max_rad[j] - q_rad[j]);
    const double room_down = std::max(0.0, q_rad[j] - limits.position_min_rad[j]);
    upper[j] = std::min(limits.speed_max_rad_per_s[j],
                        std::sqrt(2.0 * limits.accel_max_rad_per_s2[j] * room_up));
    lower[j] = -std::min(limits.speed_max_rad_per_s[j],
                         std::sqrt(2.0 * limits.accel_max_rad_per_s2[j] * room_down));
    const double margin =
        params.limit_margin_fraction * (limits.position_max_rad[j] - limits.position_min_rad[j]);
    if (room_up < margin) {
      avoidance[j] = -params.limit_avoidance_gain * (margin - room_up);
    } else if (room_down < margin) {
      avoidance[j] = params.limit_avoidance_gain * (margin - room_down);
    }
  }

  // Clamp the joint that overshoots its bound most, re-solve the task with the rest; repeat.
  std::vector<bool> active(static_cast<std::size_t>(n), true);
  Eigen::VectorXd velocity = Eigen::VectorXd::Zero(n);
  for (Eigen::Index iteration = 0; iteration <= n; ++iteration) {
    std::vector<Eigen::Index> columns;
    Eigen::Matrix<double, 6, 1> remaining_twist = twist;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (active[static_cast<std::size_t>(j)]) {
        columns.push_back(j);
      } else {
        remaining_twist -= jacobian.col(j) * velocity[j];
      }
    }
    if (columns.empty()) {
      break;
    }
    Eigen::MatrixXd active_jacobian(6, static_cast<Eigen::Index>(columns.size()));
    Eigen::VectorXd active_avoidance(static_cast<Eigen::Index>(columns.size()));
    for (std::size_t k = 0; k < columns.size(); ++k) {
      active_jacobian.col(static_cast<Eigen::Index>(k)) = jacobian.col(columns[k]);
      active_avoidance[static_cast<Eigen::Index>(k)] = avoidance[columns[k]];
    }
    const DampedInverse inverse = damped_inverse(active_jacobian, params);
    if (iteration == 0) {
      result.min_singular_value = inverse.min_singular_value;
      result.damped = inverse.damped;
    }
    const Eigen::MatrixXd null_projector =
        Eigen::MatrixXd::Identity(active_jacobian.cols(), active_jacobian.cols()) -
        inverse.pseudo_inverse * active_jacobian;
    const Eigen::VectorXd active_velocity =
        inverse.pseudo_inverse * remaining_twist + null_projector * active_avoidance;

    Eigen::Index worst = -1;
    double worst_excess = 0.0;
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const Eigen::Index j = columns[k];
      velocity[j] = active_velocity[static_cast<Eigen::Index>(k)];
      const double excess =
          std::max(velocity[j] - upper[j], lower[j] - velocity[j]) / limits.speed_max_rad_per_s[j];
      // Only position-limit bounds are clamped here; pure speed excess is handled by scaling.
      const bool position_bound =
          upper[j] < limits.speed_max_rad_per_s[j] || lower[j] > -limits.speed_max_rad_per_s[j];
      if (position_bound && excess > worst_excess) {
        worst_excess = excess;
        worst = j;
      }
    }
    if (worst < 0) {
      break;
    }
    velocity[worst] = std::clamp(velocity[worst], lower[worst], upper[worst]);
    active[static_cast<std::size_t>(worst)] = false;
    ++result.joints_limited;
  }

  // One factor for all joints keeps the direction of motion.  Bounds contain zero, so scaling
  // down never breaks a position bound.
  double scale = 1.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (velocity[j] > upper[j] && velocity[j] > 0.0) {
      scale = std::min(scale, upper[j] / velocity[j]);
    } else if (velocity[j] < lower[j] && velocity[j] < 0.0) {
      scale = std::min(scale, lower[j] / velocity[j]);
    }
  }
  result.speed_scale = scale;
  result.joint_velocity_rad_per_s = velocity * scale;
  return result;
}

}  // namespace rigger::sim
