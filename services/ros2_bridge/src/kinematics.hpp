#pragma once
/// @file
/// Forward kinematics of a serial arm of revolute joints, for turning a ROS 2 driver's joint states into
/// rigger's RobotState (flange and tool pose, tool twist). Two ways to write the arm, both exact:
///   - standard Denavit-Hartenberg rows (as UR, KUKA and most vendors publish them): frame i follows frame
///     i-1 by Rz(theta_i + theta_offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i), joint i turning about z_{i-1};
///   - a chain of fixed transforms and joint axes, as URDF writes it: joint i's frame is the previous one
///     moved by `origin`, then turned by q_i about `axis` (in that frame).
/// DH rows are converted to the chain form, so both are evaluated by the same code. Pure: no DDS, no
/// wire types. Thread-safe for concurrent const use.

#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigger::ros2_bridge {

/// A revolute joint in the chain form (URDF's <origin> and <axis>).
struct RevoluteJoint {
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< from the previous joint's frame (or the base)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           ///< unit axis in the joint's frame
};

/// One standard Denavit-Hartenberg row: T = Rz(q + theta_offset_rad) Tz(d_m) Tx(a_m) Rx(alpha_rad).
struct DhRow {
  double d_m = 0.0;
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double theta_offset_rad = 0.0;
};

/// The result of one evaluation, all in the robot's base frame.
struct ArmState {
  Eigen::Isometry3d pose_base_flange = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_base_tool = Eigen::Isometry3d::Identity();
  /// Linear velocity of the tool point (m/s) and angular velocity (rad/s), base frame: J(q) q̇.
  Eigen::Vector3d tool_linear_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d tool_angular_radps = Eigen::Vector3d::Zero();
};

/// A serial arm of revolute joints: base → joints → flange → tool.
class SerialChain {
 public:
  /// From standard DH rows. `pose_base_dh0`: the robot's base frame to DH frame 0 (identity when they are
  /// the same); `pose_dhn_flange`: DH frame n to the flange (identity when frame n is the flange).
  /// @throws std::invalid_argument when there are no rows or a value is not finite.
  static SerialChain from_dh(const std::vector<DhRow>& rows,
                             const Eigen::Isometry3d& pose_base_dh0 = Eigen::Isometry3d::Identity(),
                             const Eigen::Isometry3d& pose_dhn_flange = Eigen::Isometry3d::Identity());
  /// From the chain form. `pose_last_flange`: the last joint's frame to the flange.
  /// @throws std::invalid_argument when there are no joints, an axis is not of length 1 (within 1e-6) or a
  /// value is not finite.
  static SerialChain from_joints(std::vector<RevoluteJoint> joints,
                                 const Eigen::Isometry3d& pose_last_flange = Eigen::Isometry3d::Identity());

  int joint_count() const { return static_cast<int>(joints_.size()); }

  /// Flange pose, tool pose (`pose_flange_tool` from the flange) and tool twist at joint positions `q_rad`
  /// and velocities `qd_radps` (both joint_count() long, chain order; the caller checks the sizes).
  ArmState evaluate(const Eigen::VectorXd& q_rad, const Eigen::VectorXd& qd_radps,
                    const Eigen::Isometry3d& pose_flange_tool) const;

  /// The geometric Jacobian of the point `p_base` carried by the last link (rows: linear, angular; base
  /// frame) at `q_rad`.
  Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian(const Eigen::VectorXd& q_rad, const Eigen::Vector3d& p_base) const;

 private:
  explicit SerialChain(std::vector<RevoluteJoint> joints, const Eigen::Isometry3d& pose_last_flange);
  /// Each joint's axis and origin in the base frame at q, and the flange pose.
  Eigen::Isometry3d forward(const Eigen::VectorXd& q_rad, Eigen::Matrix3Xd& axes_base,
                            Eigen::Matrix3Xd& origins_base) const;
  static Eigen::Matrix<double, 6, Eigen::Dynamic> point_jacobian(const Eigen::Matrix3Xd& axes_base,
                                                                 const Eigen::Matrix3Xd& origins_base,
                                                                 const Eigen::Vector3d& p_base);

  std::vector<RevoluteJoint> joints_;
  Eigen::Isometry3d pose_last_flange_ = Eigen::Isometry3d::Identity();
};

}  // namespace rigger::ros2_bridge
