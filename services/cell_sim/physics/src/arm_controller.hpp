#pragma once
// Internal: the arm's motion controller, as a robot controller's interpolator runs it at 1 kHz.
// It turns commands (joint or Cartesian point-to-point, Cartesian twist, stop) into a joint
// reference (position, velocity, acceleration) within the joint and Cartesian limits.  The joint
// servo that tracks the reference lives in CellPhysics (it needs the dynamics).

#include <optional>

#include "arm_kinematics.hpp"
#include "rigger/sim/resolved_rate.hpp"
#include "rigger/sim/trapezoid_profile.hpp"

namespace rigger::sim::detail {

class ArmController {
 public:
  /// `kinematics` must outlive the controller.
  ArmController(const ArmKinematics& kinematics, const ArmLimits& limits,
                const CartesianLimits& cartesian_limits, double twist_timeout_s);

  /// Hold still at q.
  void reset(const JointVector& q_rad);
  /// Takes over `other`'s state (reference, mode, motion and its numbering), for a model built anew with the
  /// same arm; the kinematics stay this controller's.
  void continue_from(const ArmController& other);

  CommandResult move_joints(const JointVector& goal_rad, double speed_fraction);
  CommandResult move_tool(const Eigen::Isometry3d& goal_base_tool, double speed_fraction);
  CommandResult set_twist(const Twist& twist_base, double now_s);
  void stop();

  /// Advances the reference by dt.  The measured joints and tool pose decide when a motion has
  /// settled at its goal.
  void update(double now_s, double dt_s, const JointVector& q_measured_rad,
              const Eigen::Isometry3d& measured_pose_base_tool);

  [[nodiscard]] IkResult solve_ik(const Eigen::Isometry3d& goal_base_tool,
                                  const JointVector* seed) const;

  [[nodiscard]] const JointVector& reference_position() const { return q_ref_; }
  [[nodiscard]] const JointVector& reference_velocity() const { return qd_ref_; }
  [[nodiscard]] const JointVector& reference_acceleration() const { return qdd_ref_; }
  [[nodiscard]] RobotMode mode() const { return mode_; }
  [[nodiscard]] const MotionState& motion() const { return motion_; }

 private:
  enum class GoalKind { Joint, Tool };
  struct Goal {
    GoalKind kind = GoalKind::Joint;
    JointVector joints = JointVector::Zero();
    Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
    double speed_fraction = 1.0;
  };

  CommandResult accept_goal(const Goal& goal);
  void begin(const Goal& goal);
  void supersede_motion(const std::string& reason);
  void fail_motion(const std::string& reason);

  void update_stopping(double dt_s);
  void update_joint_motion(double dt_s);
  void update_cartesian_motion(double dt_s);
  void update_twist(double now_s, double dt_s);
  void update_settling(double dt_s, const JointVector& q_measured_rad,
                       const Eigen::Isometry3d& measured_pose_base_tool);

  /// Moves qd_ref towards `target` within the joint acceleration limits (one factor for all
  /// joints), integrates q_ref and keeps it inside the software limits.
  void apply_velocity(const JointVector& target_rad_per_s, double dt_s);
  [[nodiscard]] bool at_rest() const;

  const ArmKinematics& kinematics_;
  ArmLimits limits_;
  CartesianLimits cartesian_limits_;
  ResolvedRateLimits rate_limits_;
  double twist_timeout_s_;

  JointVector q_ref_ = JointVector::Zero();
  JointVector qd_ref_ = JointVector::Zero();
  JointVector qdd_ref_ = JointVector::Zero();
  RobotMode mode_ = RobotMode::Hold;
  MotionState motion_;
  std::uint64_t last_motion_id_ = 0;

  std::optional<Goal> pending_;  // starts once the arm is at rest
  Goal goal_;
  TrapezoidProfile profile_;
  double profile_time_s_ = 0.0;
  JointVector joint_start_ = JointVector::Zero();
  Eigen::Isometry3d tool_start_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d tool_rotation_ = Eigen::Vector3d::Zero();  // start to goal, base frame
  double path_end_time_s_ = 0.0;  // time spent converging after the profile ended

  bool settling_ = false;
  double settle_time_s_ = 0.0;

  Twist twist_command_;
  Twist twist_reference_;
  double twist_time_s_ = 0.0;
};

}  // namespace rigger::sim::detail
