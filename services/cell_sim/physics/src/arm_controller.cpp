#include "arm_controller.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "rigger/sim/pose_math.hpp"

namespace rigger::sim::detail {
namespace {

// Cartesian path tracking: feedback gain on the reference's pose error (1/s), and the error at
// which the path counts as not trackable (joint limit, singularity).
constexpr double kPathGainPerS = 20.0;
constexpr double kMaxPathErrorM = 0.01;
constexpr double kMaxPathErrorRad = 0.035;
constexpr double kPathConvergedM = 1e-5;
constexpr double kPathConvergedRad = 1e-4;
constexpr double kPathConvergeTimeoutS = 0.5;

// A motion has settled when the measured arm is this close to the goal; it fails when it does not
// get there in time (blocked, overloaded).
constexpr double kSettleJointRad = 2e-3;
constexpr double kSettlePositionM = 1.5e-3;
constexpr double kSettleRotationRad = 5e-3;
constexpr double kSettleTimeoutS = 3.0;

constexpr double kRestSpeedRadPerS = 1e-6;

Eigen::VectorXd to_dynamic(const JointVector& value) { return Eigen::VectorXd(value); }

std::string joint_name(int j) { return "A" + std::to_string(j + 1); }

bool finite_pose(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

// Scales a twist so that neither its linear nor its angular part exceeds the limits; one factor
// for both keeps the direction of the motion.
Twist limit_twist(const Twist& twist, double linear_limit, double angular_limit) {
  double scale = 1.0;
  const double linear = twist.linear_mps.norm();
  const double angular = twist.angular_rad_per_s.norm();
  if (linear > linear_limit) {
    scale = std::min(scale, linear_limit / linear);
  }
  if (angular > angular_limit) {
    scale = std::min(scale, angular_limit / angular);
  }
  Twist limited;
  limited.linear_mps = twist.linear_mps * scale;
  limited.angular_rad_per_s = twist.angular_rad_per_s * scale;
  return limited;
}

Eigen::Vector3d step_towards(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                             double max_step) {
  const Eigen::Vector3d delta = to - from;
  const double norm = delta.norm();
  return norm <= max_step ? to : Eigen::Vector3d(from + delta * (max_step / norm));
}

}  // namespace

ArmController::ArmController(const ArmKinematics& kinematics, const ArmLimits& limits,
                             const CartesianLimits& cartesian_limits, double twist_timeout_s)
    : kinematics_(kinematics),
      limits_(limits),
      cartesian_limits_(cartesian_limits),
      twist_timeout_s_(twist_timeout_s) {
  rate_limits_.position_min_rad = to_dynamic(limits_.position_min_rad);
  rate_limits_.position_max_rad = to_dynamic(limits_.position_max_rad);
  rate_limits_.speed_max_rad_per_s = to_dynamic(limits_.speed_max_rad_per_s);
  rate_limits_.accel_max_rad_per_s2 = to_dynamic(limits_.accel_max_rad_per_s2);
}

void ArmController::reset(const JointVector& q_rad) {
  q_ref_ = q_rad.cwiseMax(limits_.position_min_rad).cwiseMin(limits_.position_max_rad);
  qd_ref_.setZero();
  qdd_ref_.setZero();
  mode_ = RobotMode::Hold;
  pending_.reset();
  settling_ = false;
}

void ArmController::continue_from(const ArmController& other) {
  limits_ = other.limits_;
  cartesian_limits_ = other.cartesian_limits_;
  rate_limits_ = other.rate_limits_;
  twist_timeout_s_ = other.twist_timeout_s_;
  q_ref_ = other.q_ref_;
  qd_ref_ = other.qd_ref_;
  qdd_ref_ = other.qdd_ref_;
  mode_ = other.mode_;
  motion_ = other.motion_;
  last_motion_id_ = other.last_motion_id_;
  pending_ = other.pending_;
  goal_ = other.goal_;
  profile_ = other.profile_;
  profile_time_s_ = other.profile_time_s_;
  joint_start_ = other.joint_start_;
  tool_start_ = other.tool_start_;
  tool_rotation_ = other.tool_rotation_;
  path_end_time_s_ = other.path_end_time_s_;
  settling_ = other.settling_;
  settle_time_s_ = other.settle_time_s_;
  twist_command_ = other.twist_command_;
  twist_reference_ = other.twist_reference_;
  twist_time_s_ = other.twist_time_s_;
}

IkResult ArmController::solve_ik(const Eigen::Isometry3d& goal_base_tool,
                                 const JointVector* seed) const {
  // The caller's seed (or the current reference) first, so that the nearest solution wins; then
  // standard elbow-up configurations for goals far from the current pose.
  std::array<JointVector, 5> seeds;
  seeds[0] = seed != nullptr ? *seed : q_ref_;
  seeds[1] = ready_joint_positions();
  seeds[2] << 0.0, 0.6, 0.0, -1.6, 0.0, 0.9, 0.0;
  seeds[3] << 0.0, 0.3, 0.0, -1.0, 0.0, -1.2, 0.0;
  seeds[4] << 0.0, -0.6, 0.0, 1.6, 0.0, -0.9, 0.0;
  IkResult best;
  for (const JointVector& candidate : seeds) {
    if (!candidate.allFinite()) {
      continue;
    }
    const IkResult result = kinematics_.solve(goal_base_tool, candidate, limits_.position_min_rad,
                                              limits_.position_max_rad);
    if (result.converged) {
      return result;
    }
    if (best.iterations == 0 || result.position_error_m < best.position_error_m) {
      best = result;
    }
  }
  return best;
}

CommandResult ArmController::move_joints(const JointVector& goal_rad, double speed_fraction) {
  if (!goal_rad.allFinite() || !std::isfinite(speed_fraction)) {
    return {CommandStatus::RejectedNonFinite, "joint goal or speed fraction is not finite", 0};
  }
  if (speed_fraction <= 0.0 || speed_fraction > 1.0) {
    return {CommandStatus::RejectedOutOfRange, "speed fraction must be in (0, 1]", 0};
  }
  for (int j = 0; j < kArmJointCount; ++j) {
    if (goal_rad[j] < limits_.position_min_rad[j] || goal_rad[j] > limits_.position_max_rad[j]) {
      std::ostringstream text;
      text << "joint " << joint_name(j) << " goal " << goal_rad[j]
           << " rad is outside the software limits [" << limits_.position_min_rad[j] << ", "
           << limits_.position_max_rad[j] << "] rad";
      return {CommandStatus::RejectedOutOfRange, text.str(), 0};
    }
  }
  Goal goal;
  goal.kind = GoalKind::Joint;
  goal.joints = goal_rad;
  goal.speed_fraction = speed_fraction;
  return accept_goal(goal);
}

CommandResult ArmController::move_tool(const Eigen::Isometry3d& goal_base_tool,
                                       double speed_fraction) {
  if (!finite_pose(goal_base_tool) || !std::isfinite(speed_fraction)) {
    return {CommandStatus::RejectedNonFinite, "tool goal or speed fraction is not finite", 0};
  }
  if (speed_fraction <= 0.0 || speed_fraction > 1.0) {
    return {CommandStatus::RejectedOutOfRange, "speed fraction must be in (0, 1]", 0};
  }
  const Eigen::Matrix3d rotation = goal_base_tool.linear();
  if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      rotation.determinant() < 0.0) {
    return {CommandStatus::RejectedOutOfRange, "tool goal orientation is not a rotation", 0};
  }
  const IkResult ik = solve_ik(goal_base_tool, nullptr);
  if (!ik.converged) {
    std::ostringstream text;
    text << "tool goal unreachable within the joint limits (best: " << ik.position_error_m * 1e3
         << " mm, " << ik.orientation_error_rad * 180.0 / M_PI << " deg off)";
    return {CommandStatus::RejectedUnreachable, text.str(), 0};
  }
  Goal goal;
  goal.kind = GoalKind::Tool;
  goal.tool = goal_base_tool;
  goal.joints = ik.position_rad;
  goal.speed_fraction = speed_fraction;
  return accept_goal(goal);
}

CommandResult ArmController::accept_goal(const Goal& goal) {
  supersede_motion("superseded by motion " + std::to_string(last_motion_id_ + 1));
  motion_.id = ++last_motion_id_;
  motion_.status = MotionStatus::Running;
  motion_.message.clear();
  if (at_rest()) {
    begin(goal);
  } else {
    // Planned from rest: stop first, then start.
    pending_ = goal;
    mode_ = RobotMode::Stopping;
  }
  return {CommandStatus::Accepted, "", motion_.id};
}

void ArmController::begin(const Goal& goal) {
  goal_ = goal;
  profile_time_s_ = 0.0;
  path_end_time_s_ = 0.0;
  settling_ = false;
  const double fraction = goal.speed_fraction;
  if (goal.kind == GoalKind::Joint) {
    joint_start_ = q_ref_;
    const Eigen::VectorXd distances = (goal.joints - q_ref_).cwiseAbs();
    profile_ = TrapezoidProfile::plan(distances, to_dynamic(limits_.speed_max_rad_per_s * fraction),
                                      to_dynamic(limits_.accel_max_rad_per_s2 * fraction))
                   .value_or(TrapezoidProfile{});
    mode_ = RobotMode::JointMotion;
  } else {
    tool_start_ = kinematics_.pose_base_tool(q_ref_);
    tool_rotation_ = rotation_error(goal.tool.linear(), tool_start_.linear());
    Eigen::Vector2d distances((goal.tool.translation() - tool_start_.translation()).norm(),
                              tool_rotation_.norm());
    const Eigen::Vector2d speeds(cartesian_limits_.linear_speed_mps * fraction,
                                 cartesian_limits_.angular_speed_rad_per_s * fraction);
    const Eigen::Vector2d accels(cartesian_limits_.linear_accel_mps2 * fraction,
                                 cartesian_limits_.angular_accel_rad_per_s2 * fraction);
    profile_ = TrapezoidProfile::plan(distances, speeds, accels).value_or(TrapezoidProfile{});
    mode_ = RobotMode::CartesianMotion;
  }
}

CommandResult ArmController::set_twist(const Twist& twist_base, double now_s) {
  if (!twist_base.linear_mps.allFinite() || !twist_base.angular_rad_per_s.allFinite()) {
    return {CommandStatus::RejectedNonFinite, "twist is not finite", 0};
  }
  twist_command_ = limit_twist(twist_base, cartesian_limits_.linear_speed_mps,
                               cartesian_limits_.angular_speed_rad_per_s);
  twist_time_s_ = now_s;
  if (mode_ != RobotMode::Twist) {
    supersede_motion("superseded by a twist command");
    pending_.reset();
    settling_ = false;
    // Continue from the reference's current tool velocity, so the switch is smooth.
    Eigen::Isometry3d pose;
    Jacobian6x7 jacobian;
    kinematics_.evaluate(q_ref_, pose, jacobian);
    const Vector6d current = jacobian * qd_ref_;
    twist_reference_.linear_mps = current.head<3>();
    twist_reference_.angular_rad_per_s = current.tail<3>();
    mode_ = RobotMode::Twist;
  }
  const bool scaled = twist_command_.linear_mps.norm() < twist_base.linear_mps.norm() - 1e-12;
  return {CommandStatus::Accepted, scaled ? "scaled down to the Cartesian speed limits" : "", 0};
}

void ArmController::stop() {
  supersede_motion("stopped");
  pending_.reset();
  settling_ = false;
  if (mode_ == RobotMode::Twist) {
    // A twist stream stops on its path, as a robot controller's path-maintaining stop does: the twist's
    // reference ramps to zero at the Cartesian limits, then the arm holds. Braking each joint at its own
    // limit instead took the tool off its line at several m/s², and a held 40 kg load then swayed against the
    // wrist for a second.
    twist_command_ = Twist{};
    twist_time_s_ = -std::numeric_limits<double>::infinity();
    return;
  }
  mode_ = RobotMode::Stopping;
}

void ArmController::supersede_motion(const std::string& reason) {
  if (motion_.status == MotionStatus::Running) {
    motion_.status = MotionStatus::Stopped;
    motion_.message = reason;
  }
}

void ArmController::fail_motion(const std::string& reason) {
  motion_.status = MotionStatus::Failed;
  motion_.message = reason;
  pending_.reset();
  settling_ = false;
  mode_ = RobotMode::Stopping;
}

bool ArmController::at_rest() const { return qd_ref_.cwiseAbs().maxCoeff() < kRestSpeedRadPerS; }

void ArmController::apply_velocity(const JointVector& target_rad_per_s, double dt_s) {
  const JointVector delta = target_rad_per_s - qd_ref_;
  double scale = 1.0;
  for (int j = 0; j < kArmJointCount; ++j) {
    const double max_change = limits_.accel_max_rad_per_s2[j] * dt_s;
    if (std::abs(delta[j]) > max_change) {
      scale = std::min(scale, max_change / std::abs(delta[j]));
    }
  }
  const JointVector previous = qd_ref_;
  qd_ref_ += scale * delta;
  qdd_ref_ = (qd_ref_ - previous) / dt_s;
  q_ref_ += qd_ref_ * dt_s;
  // Last line of defence: the reference never leaves the software limits.
  for (int j = 0; j < kArmJointCount; ++j) {
    if (q_ref_[j] > limits_.position_max_rad[j]) {
      q_ref_[j] = limits_.position_max_rad[j];
      qd_ref_[j] = std::min(0.0, qd_ref_[j]);
    } else if (q_ref_[j] < limits_.position_min_rad[j]) {
      q_ref_[j] = limits_.position_min_rad[j];
      qd_ref_[j] = std::max(0.0, qd_ref_[j]);
    }
  }
}

void ArmController::update(double now_s, double dt_s, const JointVector& q_measured_rad,
                           const Eigen::Isometry3d& measured_pose_base_tool) {
  if (dt_s <= 0.0) {
    return;
  }
  switch (mode_) {
    case RobotMode::Hold:
      qd_ref_.setZero();
      qdd_ref_.setZero();
      break;
    case RobotMode::Stopping:
      update_stopping(dt_s);
      break;
    case RobotMode::JointMotion:
      update_joint_motion(dt_s);
      break;
    case RobotMode::CartesianMotion:
      update_cartesian_motion(dt_s);
      break;
    case RobotMode::Twist:
      update_twist(now_s, dt_s);
      break;
  }
  if (settling_) {
    update_settling(dt_s, q_measured_rad, measured_pose_base_tool);
  }
}

void ArmController::update_stopping(double dt_s) {
  apply_velocity(JointVector::Zero(), dt_s);
  if (!at_rest()) {
    return;
  }
  qd_ref_.setZero();
  qdd_ref_.setZero();
  mode_ = RobotMode::Hold;
  if (pending_) {
    const Goal goal = *pending_;
    pending_.reset();
    begin(goal);
  }
}

void ArmController::update_joint_motion(double dt_s) {
  profile_time_s_ += dt_s;
  const TrapezoidProfile::Sample sample = profile_.sample(profile_time_s_);
  const JointVector delta = goal_.joints - joint_start_;
  q_ref_ = joint_start_ + delta * sample.s;
  qd_ref_ = delta * sample.ds;
  qdd_ref_ = delta * sample.dds;
  if (profile_time_s_ >= profile_.duration_s()) {
    q_ref_ = goal_.joints;
    qd_ref_.setZero();
    qdd_ref_.setZero();
    mode_ = RobotMode::Hold;
    settling_ = true;
    settle_time_s_ = 0.0;
  }
}

void ArmController::update_cartesian_motion(double dt_s) {
  const TrapezoidProfile::Sample sample = profile_.sample(profile_time_s_);
  const Eigen::Vector3d translation = goal_.tool.translation() - tool_start_.translation();
  Eigen::Isometry3d desired = Eigen::Isometry3d::Identity();
  desired.translation() = tool_start_.translation() + translation * sample.s;
  desired.linear() = rotation_from_vector(tool_rotation_ * sample.s) * tool_start_.linear();
  Vector6d feedforward;
  feedforward.head<3>() = translation * sample.ds;
  feedforward.tail<3>() = tool_rotation_ * sample.ds;

  Eigen::Isometry3d reference_pose;
  Jacobian6x7 jacobian;
  kinematics_.evaluate(q_ref_, reference_pose, jacobian);
  const Vector6d error = pose_error(desired, reference_pose);
  if (error.head<3>().norm() > kMaxPathErrorM || error.tail<3>().norm() > kMaxPathErrorRad) {
    std::ostringstream text;
    text << "path not trackable at " << std::lround(100.0 * sample.s)
         << " % (joint limit or singularity): reference off by " << error.head<3>().norm() * 1e3
         << " mm, " << error.tail<3>().norm() * 180.0 / M_PI << " deg";
    fail_motion(text.str());
    return;
  }

  const bool profile_done = profile_time_s_ >= profile_.duration_s();
  const Vector6d command = (profile_done ? Vector6d::Zero() : feedforward) + kPathGainPerS * error;
  const ResolvedRateResult rate =
      solve_resolved_rate(jacobian, command, to_dynamic(q_ref_), rate_limits_);
  apply_velocity(JointVector(rate.joint_velocity_rad_per_s), dt_s);
  // When the joints cannot keep up, slow the path down rather than fall behind it.
  profile_time_s_ += rate.speed_scale * dt_s;

  if (profile_done) {
    path_end_time_s_ += dt_s;
    const bool converged =
        error.head<3>().norm() < kPathConvergedM && error.tail<3>().norm() < kPathConvergedRad;
    if (converged || path_end_time_s_ > kPathConvergeTimeoutS) {
      qd_ref_.setZero();
      qdd_ref_.setZero();
      mode_ = RobotMode::Hold;
      settling_ = true;
      settle_time_s_ = 0.0;
    }
  }
}

void ArmController::update_twist(double now_s, double dt_s) {
  const bool fresh = now_s - twist_time_s_ <= twist_timeout_s_;
  const Twist command = fresh ? twist_command_ : Twist{};
  twist_reference_.linear_mps = step_towards(twist_reference_.linear_mps, command.linear_mps,
                                             cartesian_limits_.linear_accel_mps2 * dt_s);
  twist_reference_.angular_rad_per_s =
      step_towards(twist_reference_.angular_rad_per_s, command.angular_rad_per_s,
                   cartesian_limits_.angular_accel_rad_per_s2 * dt_s);

  JointVector target = JointVector::Zero();
  const bool moving =
      twist_reference_.linear_mps.squaredNorm() + twist_reference_.angular_rad_per_s.squaredNorm() >
      1e-18;
  if (moving) {
    Eigen::Isometry3d pose;
    Jacobian6x7 jacobian;
    kinematics_.evaluate(q_ref_, pose, jacobian);
    Vector6d twist;
    twist << twist_reference_.linear_mps, twist_reference_.angular_rad_per_s;
    target = solve_resolved_rate(jacobian, twist, to_dynamic(q_ref_), rate_limits_)
                 .joint_velocity_rad_per_s;
  }
  apply_velocity(target, dt_s);
  if (!moving && at_rest()) {
    qd_ref_.setZero();
    qdd_ref_.setZero();
    if (!fresh) {
      mode_ = RobotMode::Hold;
    }
  }
}

void ArmController::update_settling(double dt_s, const JointVector& q_measured_rad,
                                    const Eigen::Isometry3d& measured_pose_base_tool) {
  if (motion_.status != MotionStatus::Running) {
    settling_ = false;
    return;
  }
  bool settled = false;
  std::ostringstream remaining;
  if (goal_.kind == GoalKind::Joint) {
    const double error = (q_measured_rad - goal_.joints).cwiseAbs().maxCoeff();
    settled = error < kSettleJointRad;
    remaining << error * 180.0 / M_PI << " deg";
  } else {
    const Vector6d error = pose_error(goal_.tool, measured_pose_base_tool);
    settled =
        error.head<3>().norm() < kSettlePositionM && error.tail<3>().norm() < kSettleRotationRad;
    remaining << error.head<3>().norm() * 1e3 << " mm, " << error.tail<3>().norm() * 180.0 / M_PI
              << " deg";
  }
  if (settled) {
    motion_.status = MotionStatus::Reached;
    motion_.message.clear();
    settling_ = false;
    return;
  }
  settle_time_s_ += dt_s;
  if (settle_time_s_ > kSettleTimeoutS) {
    motion_.status = MotionStatus::Failed;
    motion_.message =
        "did not settle at the goal (blocked or overloaded?): still " + remaining.str() + " off";
    settling_ = false;
  }
}

}  // namespace rigger::sim::detail
