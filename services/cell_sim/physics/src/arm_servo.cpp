// CellPhysics's arm: the computed-torque joint servo, with the feed-forward and damping of the payload
// the magnet holds.
#include <algorithm>
#include <cmath>

#include "cell_physics_impl.hpp"

namespace rigger::sim {
namespace {

// Joint servo bandwidth (rad/s) and damping ratio: computed torque with the model's mass matrix,
// as stiff as a position-controlled industrial arm.
constexpr double kServoBandwidthRadPerS = 80.0;
constexpr double kServoDampingRatio = 1.0;
// The joints whose velocity feedback carries the held payload's reflected inertia (A1 to A5; see
// add_payload_inertia). A6 and A7, whose axes pass next to the magnet, keep the arm's own: damped for the
// payload, they held the tool's orientation against the load so stiffly that a slow pull off the face
// peeled the grip at 54-70 % of its rating (GripperPhysics' WeakGrasp tests; 87-99 % without).
constexpr int kPayloadDampedJoints = 5;
// That damping blends in over this time after the magnet grips (s), as a controller given new load data
// would. Switched on at once, it met a load still swinging on its rope with the full damping: the slip
// scenario's retry then failed once on the grip's yank at the wrist (2,093 N/s against the yank monitor's
// 2,000 N/s; the grip alone is ~1,000 N/s). Blended in, that scenario passed twice.
constexpr double kPayloadDampingBlendS = 0.5;

}  // namespace

void CellPhysics::Impl::control_arm(double dt_s) {
  const JointVector q = joint_positions();
  const JointVector qd = joint_velocities();
  const Eigen::Isometry3d measured_pose_base_tool =
      pose_world_base.inverse() * site_pose_world(index.tool_site);
  arm->update(now_s(), dt_s, q, measured_pose_base_tool);

  // Computed-torque joint servo: M (qdd_ref + Kd e_dot + Kp e) + bias, with the friction the
  // model has compensated, clipped to the motors' torque limits.
  const double kp = kServoBandwidthRadPerS * kServoBandwidthRadPerS;
  const double kd = 2.0 * kServoDampingRatio * kServoBandwidthRadPerS;
  const JointVector accel = arm->reference_acceleration() + kd * (arm->reference_velocity() - qd) +
                            kp * (arm->reference_position() - q);
  std::fill(servo_acceleration.begin(), servo_acceleration.end(), 0.0);
  for (int j = 0; j < kArmJointCount; ++j) {
    servo_acceleration[static_cast<std::size_t>(index.arm[static_cast<std::size_t>(j)].dof)] =
        accel[j];
  }
  mj_mulM(model.get(), data.get(), servo_force.data(), servo_acceleration.data());
  const JointVector payload_inertia = holding && held_body >= 0
                                          ? add_payload_inertia(arm->reference_acceleration())
                                          : JointVector::Zero();
  const JointVector qd_ref = arm->reference_velocity();
  held_s = holding ? held_s + dt_s : 0.0;
  for (int j = 0; j < kArmJointCount; ++j) {
    const int dof = index.arm[static_cast<std::size_t>(j)].dof;
    // The payload's share of the drive's velocity feedback (see add_payload_inertia): c (q̇_ref - q̇), part of
    // the motor torque and clipped with it. Its -c q̇ is also the model's joint damping, so that the Euler
    // step integrates it implicitly (at the next step's velocity): stable however heavy the payload. The
    // passive force mj_step1 computed with the previous step's c is cancelled through qfrc_applied (it is
    // accounted for in the torque); the model's own passive forces are compensated as before.
    const double previous_damping = model->dof_damping[dof] - joint_model_damping[j];
    const double payload_damping =
        j < kPayloadDampedJoints ? std::min(1.0, held_s / kPayloadDampingBlendS) * kd * payload_inertia[j] : 0.0;
    const double model_passive = data->qfrc_passive[dof] + previous_damping * qd[j];
    const double torque = servo_force[static_cast<std::size_t>(dof)] + data->qfrc_bias[dof] - model_passive +
                          payload_damping * (qd_ref[j] - qd[j]);
    joint_torque[j] = std::clamp(torque, -arm_limits.torque_max_nm[j], arm_limits.torque_max_nm[j]);
    data->ctrl[index.arm_actuator[static_cast<std::size_t>(j)]] = joint_torque[j];
    data->qfrc_applied[dof] = previous_damping * qd[j];
    model->dof_damping[dof] = joint_model_damping[j] + payload_damping;
  }
}

// A robot controller's dynamic model includes the payload its load data describe. Without it the servo's
// computed torque is sized for the arm alone: decelerating a 40 kg load, the arm fell behind its reference and
// the load then swayed against the wrist at ~2 Hz, barely damped (19 mm/s at the tool, still 2 mm/s 1.5 s
// later: GripperPhysics.AHeldLoadStopsWithTheArm). So while the magnet holds a body, the torque that the
// reference's acceleration needs to move that body rigidly with the gripper is fed forward:
// τ = Jpᵀ m Jp q̈_ref + Jrᵀ I Jr q̈_ref, with Jp, Jr the gripper's Jacobian at the body's centre of mass (the
// sway then starts at ~3.5 mm/s). The feedback gains stay the arm's own: scaled up for the payload, the arm
// side of the magnet's spring-damper went unstable at the 1 ms step (the grip chattered and let go). The
// body's weight is not fed forward: the crane's rope carries the load, and a controller that compensated it
// would push the load up the rope. Returns the payload's inertia reflected to each joint, for the payload's
// share of the velocity feedback (control_arm): kd times it, as joint damping relative to the reference that
// the Euler step integrates implicitly, so that it damps the sway that is left (a held-load stop settles
// below 1 mm/s 136 ms after the twist reached zero instead of 724 ms) without the instability of explicit
// gains; the stiffness stays the arm's own.
JointVector CellPhysics::Impl::add_payload_inertia(const JointVector& joint_acceleration) {
  const int nv = model->nv;
  mj_jac(model.get(), data.get(), payload_jacp.data(), payload_jacr.data(), data->xipos + 3 * held_body,
         index.gripper_body);
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  for (int j = 0; j < kArmJointCount; ++j) {
    const int dof = index.arm[static_cast<std::size_t>(j)].dof;
    const double qdd = joint_acceleration[j];
    for (int r = 0; r < 3; ++r) {
      linear[r] += payload_jacp[static_cast<std::size_t>(r * nv + dof)] * qdd;
      angular[r] += payload_jacr[static_cast<std::size_t>(r * nv + dof)] * qdd;
    }
  }
  const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> rotation(data->ximat + 9 * held_body);
  const Eigen::Matrix3d inertia_world =
      rotation * vec3(model->body_inertia + 3 * held_body).asDiagonal() * rotation.transpose();
  const Eigen::Vector3d force = model->body_mass[held_body] * linear;
  const Eigen::Vector3d torque = inertia_world * angular;
  for (int j = 0; j < kArmJointCount; ++j) {
    const int dof = index.arm[static_cast<std::size_t>(j)].dof;
    double extra = 0.0;
    for (int r = 0; r < 3; ++r) {
      extra += payload_jacp[static_cast<std::size_t>(r * nv + dof)] * force[r] +
               payload_jacr[static_cast<std::size_t>(r * nv + dof)] * torque[r];
    }
    servo_force[static_cast<std::size_t>(dof)] += extra;
  }
  // The payload's inertia reflected to each joint alone (the diagonal of Jpᵀ m Jp + Jrᵀ I Jr).
  JointVector reflected = JointVector::Zero();
  for (int j = 0; j < kArmJointCount; ++j) {
    const int dof = index.arm[static_cast<std::size_t>(j)].dof;
    Eigen::Vector3d jp;
    Eigen::Vector3d jr;
    for (int r = 0; r < 3; ++r) {
      jp[r] = payload_jacp[static_cast<std::size_t>(r * nv + dof)];
      jr[r] = payload_jacr[static_cast<std::size_t>(r * nv + dof)];
    }
    reflected[j] = model->body_mass[held_body] * jp.squaredNorm() + jr.dot(inertia_world * jr);
  }
  return reflected;
}

}  // namespace rigger::sim
