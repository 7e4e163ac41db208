#include "kinematics.hpp"

#include <cmath>
#include <string>

namespace rigger::ros2_bridge {
namespace {

bool finite(const Eigen::Isometry3d& t) {
  return t.matrix().allFinite();
}

// Rz(theta_offset) Tz(d) Tx(a) Rx(alpha): the fixed part of a DH row, after the joint's own Rz(q).
Eigen::Isometry3d dh_fixed(const DhRow& r) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.rotate(Eigen::AngleAxisd(r.theta_offset_rad, Eigen::Vector3d::UnitZ()));
  t.translate(Eigen::Vector3d(0.0, 0.0, r.d_m));
  t.translate(Eigen::Vector3d(r.a_m, 0.0, 0.0));
  t.rotate(Eigen::AngleAxisd(r.alpha_rad, Eigen::Vector3d::UnitX()));
  return t;
}

}  // namespace

SerialChain::SerialChain(std::vector<RevoluteJoint> joints, const Eigen::Isometry3d& pose_last_flange)
    : joints_(std::move(joints)), pose_last_flange_(pose_last_flange) {}

SerialChain SerialChain::from_dh(const std::vector<DhRow>& rows, const Eigen::Isometry3d& pose_base_dh0,
                                 const Eigen::Isometry3d& pose_dhn_flange) {
  if (rows.empty()) throw std::invalid_argument("no DH rows");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const DhRow& r = rows[i];
    if (!std::isfinite(r.d_m) || !std::isfinite(r.a_m) || !std::isfinite(r.alpha_rad) ||
        !std::isfinite(r.theta_offset_rad))
      throw std::invalid_argument("DH row " + std::to_string(i) + " has a value that is not finite");
  }
  if (!finite(pose_base_dh0) || !finite(pose_dhn_flange)) throw std::invalid_argument("a fixed pose is not finite");
  // base · Rz(q1) M1 · Rz(q2) M2 ⋯ Rz(qn) Mn · flange: joint i turns about z after the previous row's fixed part.
  std::vector<RevoluteJoint> joints(rows.size());
  joints[0].origin = pose_base_dh0;
  for (std::size_t i = 1; i < rows.size(); ++i) joints[i].origin = dh_fixed(rows[i - 1]);
  return SerialChain(std::move(joints), dh_fixed(rows.back()) * pose_dhn_flange);
}

SerialChain SerialChain::from_joints(std::vector<RevoluteJoint> joints, const Eigen::Isometry3d& pose_last_flange) {
  if (joints.empty()) throw std::invalid_argument("no joints");
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (!finite(joints[i].origin) || !joints[i].axis.allFinite())
      throw std::invalid_argument("joint " + std::to_string(i) + " has a value that is not finite");
    if (std::abs(joints[i].axis.norm() - 1.0) > 1e-6)
      throw std::invalid_argument("joint " + std::to_string(i) + "'s axis is not of length 1");
    joints[i].axis.normalize();
  }
  if (!finite(pose_last_flange)) throw std::invalid_argument("the flange pose is not finite");
  return SerialChain(std::move(joints), pose_last_flange);
}

Eigen::Isometry3d SerialChain::forward(const Eigen::VectorXd& q_rad, Eigen::Matrix3Xd& axes_base,
                                       Eigen::Matrix3Xd& origins_base) const {
  const int n = joint_count();
  axes_base.resize(3, n);
  origins_base.resize(3, n);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < n; ++i) {
    const RevoluteJoint& j = joints_[static_cast<std::size_t>(i)];
    t = t * j.origin;
    axes_base.col(i) = t.linear() * j.axis;
    origins_base.col(i) = t.translation();
    t.rotate(Eigen::AngleAxisd(q_rad[i], j.axis));
  }
  return t * pose_last_flange_;
}

ArmState SerialChain::evaluate(const Eigen::VectorXd& q_rad, const Eigen::VectorXd& qd_radps,
                               const Eigen::Isometry3d& pose_flange_tool) const {
  Eigen::Matrix3Xd axes, origins;
  ArmState out;
  out.pose_base_flange = forward(q_rad, axes, origins);
  out.pose_base_tool = out.pose_base_flange * pose_flange_tool;
  const Eigen::Matrix<double, 6, 1> twist = point_jacobian(axes, origins, out.pose_base_tool.translation()) * qd_radps;
  out.tool_linear_mps = twist.head<3>();
  out.tool_angular_radps = twist.tail<3>();
  return out;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> SerialChain::jacobian(const Eigen::VectorXd& q_rad,
                                                               const Eigen::Vector3d& p_base) const {
  Eigen::Matrix3Xd axes, origins;
  forward(q_rad, axes, origins);
  return point_jacobian(axes, origins, p_base);
}

Eigen::Matrix<double, 6, Eigen::Dynamic> SerialChain::point_jacobian(const Eigen::Matrix3Xd& axes_base,
                                                                     const Eigen::Matrix3Xd& origins_base,
                                                                     const Eigen::Vector3d& p_base) {
  // Revolute joint i moves the point at z_i × (p - o_i) per rad/s and turns it at z_i.
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, axes_base.cols());
  for (Eigen::Index i = 0; i < axes_base.cols(); ++i) {
    j.block<3, 1>(0, i) = axes_base.col(i).cross(p_base - origins_base.col(i));
    j.block<3, 1>(3, i) = axes_base.col(i);
  }
  return j;
}

}  // namespace rigger::ros2_bridge
