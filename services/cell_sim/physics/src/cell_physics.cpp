#include "rigger/sim/cell_physics.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "arm_controller.hpp"
#include "arm_kinematics.hpp"
#include "rigger/base/install.hpp"
#include "cell_model.hpp"
#include "rigger/sim/iiwa14.hpp"
#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

using Clock = std::chrono::steady_clock;

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

// Hoist load cell: low-pass time constant (s).
constexpr double kLoadCellTimeConstantS = 0.5;

// Crane velocity setpoints above this are nonsense, not something to clamp (m/s).
constexpr double kMaxCraneSetpointMps = 10.0;

// External forces beyond this are refused (N): a person or a test, not a crash.
constexpr double kMaxLoadExternalForceN = 1.0e5;

constexpr const char* kWarningNames[mjNWARNING] = {"near-singular inertia",
                                                   "contact buffer full",
                                                   "constraint buffer full",
                                                   "visual geom buffer full",
                                                   "bad qpos",
                                                   "bad qvel",
                                                   "bad qacc (state reset)",
                                                   "bad ctrl"};

Eigen::Vector3d vec3(const mjtNum* values) { return {values[0], values[1], values[2]}; }

void add_wrench_at(mjData& data, int body, const Eigen::Vector3d& force,
                   const Eigen::Vector3d& torque, const Eigen::Vector3d& point_world) {
  // xfrc_applied is (force, torque) at the body's centre of mass, world frame.
  const Eigen::Vector3d lever = point_world - vec3(data.xipos + 3 * body);
  const Eigen::Vector3d total_torque = torque + lever.cross(force);
  for (int i = 0; i < 3; ++i) {
    data.xfrc_applied[6 * body + i] += force[i];
    data.xfrc_applied[6 * body + 3 + i] += total_torque[i];
  }
}

// Linear and angular velocity of a body at a world point.
void body_point_velocity(const mjModel& model, const mjData& data, int body,
                         const Eigen::Vector3d& point_world, Eigen::Vector3d& linear,
                         Eigen::Vector3d& angular) {
  mjtNum velocity[6];
  mj_objectVelocity(&model, &data, mjOBJ_BODY, body, velocity, 0);
  angular = vec3(velocity);
  linear = vec3(velocity + 3) + angular.cross(point_world - vec3(data.xpos + 3 * body));
}

ArmLimits make_arm_limits(double margin_rad) {
  ArmLimits limits;
  limits.hard_position_max_rad = iiwa14::position_limits_rad();
  const JointVector margin = JointVector::Constant(std::max(0.0, margin_rad));
  limits.position_max_rad = limits.hard_position_max_rad - margin;
  limits.position_min_rad = -limits.position_max_rad;
  limits.speed_max_rad_per_s = iiwa14::speed_limits_rad_per_s();
  limits.accel_max_rad_per_s2 = iiwa14::acceleration_limits_rad_per_s2();
  limits.torque_max_nm = iiwa14::torque_limits_nm();
  return limits;
}

}  // namespace

std::filesystem::path default_model_path() { return find_data_path("cell_sim/cell.xml").path; }

JointVector ready_joint_positions() {
  // A2 + A4 (about -y) + A6 add up to 90 deg: the flange points along +x, tool x down.
  return (JointVector() << 0.0, 0.393, 0.0, -1.986, 0.0, -0.808, 0.0).finished();
}

struct CellPhysics::Impl {
  Impl(const CellGeometry& cell_geometry, const CellPhysicsOptions& physics_options);

  void substep();
  void control_crane(double dt_s);
  void control_arm(double dt_s);
  JointVector add_payload_inertia(const JointVector& joint_acceleration);
  void control_gripper(double dt_s);
  void record_wrench();
  int aligned_face_contact() const;
  MagnetSpring magnet_spring_for(int body) const;
  JointVector joint_positions() const;
  JointVector joint_velocities() const;
  Eigen::Isometry3d site_pose_world(int site) const;
  Eigen::Isometry3d body_pose_world(int body) const;
  double now_s() const { return static_cast<double>(steps) * timestep_s; }
  void run_steps(std::uint64_t count);

  CellGeometry cell;
  CellPhysicsOptions options;
  detail::ModelPtr model;
  detail::DataPtr data;
  detail::CellModelIndex index;
  ArmLimits arm_limits;
  std::unique_ptr<detail::ArmKinematics> kinematics;
  std::unique_ptr<detail::ArmController> arm;
  Eigen::Isometry3d pose_world_base = Eigen::Isometry3d::Identity();

  double timestep_s = 0.001;
  std::chrono::nanoseconds timestep_ns{1000000};
  std::uint64_t steps = 0;
  Clock::duration wall_stepping{0};

  // Crane.
  TravelDrive bridge;
  TravelDrive trolley;
  HoistDrum drum;
  bool crane_frozen = false;
  Eigen::Vector3d crane_setpoint_mps = Eigen::Vector3d::Zero();
  double rope_tension = 0.0;
  double load_mass_estimate = 0.0;
  double hook_mass_kg = 0.0;

  // Arm servo.
  JointVector joint_torque = JointVector::Zero();
  JointVector joint_model_damping = JointVector::Zero();  // the model's own joint damping (N m s/rad)
  std::vector<mjtNum> servo_acceleration;
  std::vector<mjtNum> servo_force;
  std::vector<mjtNum> payload_jacp;  // 3 x nv, row major: the gripper's Jacobian at the payload's centre of mass
  std::vector<mjtNum> payload_jacr;

  // Gripper.
  MagnetGripLogic magnet;
  MagnetCapacity capacity;
  bool holding = false;
  bool face_in_contact = false;
  int held_body = -1;  // the load's or the part's body while holding
  double held_s = 0.0;  // how long the magnet has held it
  double utilisation = 0.0;
  Eigen::Vector3d anchor_load = Eigen::Vector3d::Zero();  // load frame
  Eigen::Matrix3d rotation_tool_load = Eigen::Matrix3d::Identity();

  Eigen::Vector3d load_force_world = Eigen::Vector3d::Zero();

  // Wrist sensor.
  Wrench wrench_raw;
  Wrench wrench_external;
  std::mt19937_64 noise_engine;
  std::normal_distribution<double> unit_normal{0.0, 1.0};
};

CellPhysics::Impl::Impl(const CellGeometry& cell_geometry,
                        const CellPhysicsOptions& physics_options)
    : cell(cell_geometry),
      options(physics_options),
      model(detail::load_model(physics_options.model_path)),
      index(detail::index_model(*model, physics_options.model_path)),
      arm_limits(make_arm_limits(physics_options.joint_limit_margin_rad)),
      bridge(TravelDrive::Params{}),
      trolley(TravelDrive::Params{}),
      drum(HoistDrum::Params{}),
      noise_engine(physics_options.noise_seed) {
  const JointVector& initial = options.initial_joint_positions_rad;
  if (!initial.allFinite() || (initial.array() < arm_limits.position_min_rad.array()).any() ||
      (initial.array() > arm_limits.position_max_rad.array()).any()) {
    throw PhysicsModelError(
        "initial joint positions must be finite and inside the software joint "
        "limits");
  }
  if (model->opt.timestep <= 0.0 || model->opt.integrator != mjINT_EULER) {
    throw PhysicsModelError(options.model_path.string() +
                            ": expected a positive timestep and the Euler integrator (the control "
                            "loop splits mj_step into mj_step1/mj_step2)");
  }
  const std::vector<mjtNum> initial_qpos =
      detail::apply_cell_geometry(*model, index, cell, initial);

  timestep_s = model->opt.timestep;
  timestep_ns = std::chrono::nanoseconds(std::llround(timestep_s * 1e9));
  data.reset(mj_makeData(model.get()));
  if (!data) {
    throw PhysicsModelError("MuJoCo could not allocate data for the model");
  }
  servo_acceleration.assign(static_cast<std::size_t>(model->nv), 0.0);
  servo_force.assign(static_cast<std::size_t>(model->nv), 0.0);
  payload_jacp.assign(3 * static_cast<std::size_t>(model->nv), 0.0);
  payload_jacr.assign(3 * static_cast<std::size_t>(model->nv), 0.0);
  for (int j = 0; j < kArmJointCount; ++j) {
    joint_model_damping[j] = model->dof_damping[index.arm[static_cast<std::size_t>(j)].dof];
  }

  const CraneGeometry& crane = cell.crane;
  // Crane drives: references stay inside the end stops; each drive's ramp is what its force limit
  // can do with the mass it moves (80 %, leaving margin for the swinging load).
  const auto drive_params = [&](const detail::JointAddress& joint, int actuator) {
    TravelDrive::Params params;
    params.position_min_m = model->jnt_range[2 * joint.id];
    params.position_max_m = model->jnt_range[2 * joint.id + 1];
    const double force_limit = std::min(std::abs(model->actuator_ctrlrange[2 * actuator]),
                                        std::abs(model->actuator_ctrlrange[2 * actuator + 1]));
    params.max_accel_mps2 = 0.8 * force_limit / model->dof_M0[joint.dof];
    return params;
  };
  bridge = TravelDrive(drive_params(index.bridge, index.bridge_actuator));
  trolley = TravelDrive(drive_params(index.trolley, index.trolley_actuator));
  HoistDrum::Params drum_params;
  drum_params.payout_min_m = crane.rope_length_range_m[0];
  drum_params.payout_max_m = crane.rope_length_range_m[1];
  drum = HoistDrum(drum_params);
  hook_mass_kg = model->body_mass[index.hook_body];

  capacity = options.magnet_capacity;
  capacity.holding_force_n = cell.gripper.holding_force_n;

  kinematics = std::make_unique<detail::ArmKinematics>(*model, index);
  pose_world_base = kinematics->pose_world_base();
  arm = std::make_unique<detail::ArmController>(
      *kinematics, arm_limits, options.cartesian_limits,
      std::chrono::duration<double>(options.twist_timeout).count());

  mj_resetData(model.get(), data.get());
  std::copy(initial_qpos.begin(), initial_qpos.end(), data->qpos);
  // The load hangs still: pre-stretch the rope by its static load so nothing jumps at start.
  const double static_tension =
      (model->body_mass[index.load_body] + hook_mass_kg) * std::abs(model->opt.gravity[2]);
  const double payout = data->qpos[index.rope_length.qpos];
  data->qpos[index.rope_length.qpos] = payout + static_tension / options.rope.stiffness_n_per_m;
  bridge.reset(data->qpos[index.bridge.qpos]);
  trolley.reset(data->qpos[index.trolley.qpos]);
  drum.reset(payout);
  arm->reset(initial);
  load_mass_estimate = model->body_mass[index.load_body];
  mj_forward(model.get(), data.get());
  record_wrench();
}

JointVector CellPhysics::Impl::joint_positions() const {
  JointVector q;
  for (int j = 0; j < kArmJointCount; ++j) {
    q[j] = data->qpos[index.arm[static_cast<std::size_t>(j)].qpos];
  }
  return q;
}

JointVector CellPhysics::Impl::joint_velocities() const {
  JointVector qd;
  for (int j = 0; j < kArmJointCount; ++j) {
    qd[j] = data->qvel[index.arm[static_cast<std::size_t>(j)].dof];
  }
  return qd;
}

Eigen::Isometry3d CellPhysics::Impl::site_pose_world(int site) const {
  return detail::to_isometry(data->site_xpos + 3 * site, data->site_xmat + 9 * site);
}

Eigen::Isometry3d CellPhysics::Impl::body_pose_world(int body) const {
  return detail::to_isometry(data->xpos + 3 * body, data->xmat + 9 * body);
}

void CellPhysics::Impl::run_steps(std::uint64_t count) {
  const Clock::time_point start = Clock::now();
  for (std::uint64_t i = 0; i < count; ++i) {
    substep();
  }
  wall_stepping += Clock::now() - start;
}

// One physics step.  Invariant between steps: mj_step1 has run for the current state, so
// positions, velocities, contacts and the mass matrix are current and the controllers read them;
// their outputs go in before mj_step2 integrates.
void CellPhysics::Impl::substep() {
  mju_zero(data->xfrc_applied, 6 * model->nbody);
  control_crane(timestep_s);
  control_arm(timestep_s);
  control_gripper(timestep_s);
  if (!load_force_world.isZero()) {
    add_wrench_at(*data, index.load_body, load_force_world, Eigen::Vector3d::Zero(),
                  vec3(data->xipos + 3 * index.load_body));
  }
  mj_step2(model.get(), data.get());
  record_wrench();  // sensors of the state just integrated from
  mj_step1(model.get(), data.get());
  ++steps;
}

void CellPhysics::Impl::control_crane(double dt_s) {
  const Eigen::Vector3d setpoint = crane_frozen ? Eigen::Vector3d::Zero() : crane_setpoint_mps;
  bridge.set_velocity_setpoint(setpoint.x());
  trolley.set_velocity_setpoint(setpoint.y());
  drum.set_velocity_setpoint(setpoint.z());

  // Travel drives: acceleration from the drive law, force through the axis' own inertia (the
  // diagonal of M: the whole crane and load the axis carries) plus the bias forces it feels.
  const auto drive_force = [&](TravelDrive& drive, const detail::JointAddress& joint) {
    const double accel = drive.update(data->qpos[joint.qpos], data->qvel[joint.dof], dt_s);
    return data->qM[model->dof_Madr[joint.dof]] * accel + data->qfrc_bias[joint.dof];
  };
  data->ctrl[index.bridge_actuator] = drive_force(bridge, index.bridge);
  data->ctrl[index.trolley_actuator] = drive_force(trolley, index.trolley);

  drum.update(dt_s);
  rope_tension =
      rope_tension_n(data->qpos[index.rope_length.qpos], data->qvel[index.rope_length.dof],
                     drum.payout_m(), drum.payout_rate_mps(), options.rope);
  // The rope pulls the hook towards the sheave: negative along the rope-length joint.
  data->ctrl[index.rope_actuator] = -rope_tension;

  const double gravity = std::abs(model->opt.gravity[2]);
  const double measured_mass = gravity > 0.0 ? rope_tension / gravity - hook_mass_kg : 0.0;
  load_mass_estimate +=
      std::min(1.0, dt_s / kLoadCellTimeConstantS) * (measured_mass - load_mass_estimate);
}

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

// The magnet's spring-damper for the body it holds. Its forces are applied explicitly (xfrc_applied), and an
// explicit spring-damper on a light body is stable at the step only while c·dt/m and k·dt²/m stay small (the
// arm's servo on the other side makes it worse: held 1.5 mm across the air gap, a 3 kg part oscillated against
// the tool at half the step rate with c·dt/m = 0.5): the gains are capped for the body's mass and smallest
// principal inertia (c ≤ 0.1 m/dt, k ≤ 0.25 m/dt²). The 40 kg load is far below the caps (it keeps the
// configured gains); a 3 kg part's damping is capped.
MagnetSpring CellPhysics::Impl::magnet_spring_for(int body) const {
  MagnetSpring params = options.magnet_spring;
  if (body < 0) return params;
  const double mass = model->body_mass[body];
  const double inertia =
      std::min({model->body_inertia[3 * body], model->body_inertia[3 * body + 1], model->body_inertia[3 * body + 2]});
  const double dt = timestep_s;
  params.damping_n_s_per_m = std::min(params.damping_n_s_per_m, 0.1 * mass / dt);
  params.stiffness_n_per_m = std::min(params.stiffness_n_per_m, 0.25 * mass / (dt * dt));
  params.rotational_damping_nm_s_per_rad = std::min(params.rotational_damping_nm_s_per_rad, 0.1 * inertia / dt);
  params.rotational_stiffness_nm_per_rad = std::min(params.rotational_stiffness_nm_per_rad, 0.25 * inertia / (dt * dt));
  return params;
}

// The body (the load's or the part's) whose box the magnet face touches flat, or -1.
int CellPhysics::Impl::aligned_face_contact() const {
  const Eigen::Vector3d tool_z = site_pose_world(index.tool_site).linear().col(2);
  const double min_cosine = std::cos(options.magnet_spring.max_contact_angle_rad);
  for (int i = 0; i < data->ncon; ++i) {
    const mjContact& contact = data->contact[i];
    int other = -1;
    if (contact.geom1 == index.gripper_face_geom) other = contact.geom2;
    if (contact.geom2 == index.gripper_face_geom) other = contact.geom1;
    if ((other == index.load_geom || other == index.part_geom) &&
        std::abs(tool_z.dot(vec3(contact.frame))) >= min_cosine) {
      return model->geom_bodyid[other];
    }
  }
  return -1;
}

void CellPhysics::Impl::control_gripper(double dt_s) {
  const int touched_body = aligned_face_contact();
  face_in_contact = touched_body >= 0;
  const Eigen::Isometry3d tool = site_pose_world(index.tool_site);
  // What the magnet holds (or is about to grip): the load or the part.
  const int grip_body = holding ? held_body : touched_body;
  const Eigen::Isometry3d load = grip_body >= 0 ? body_pose_world(grip_body) : Eigen::Isometry3d::Identity();

  // The magnet as a stiff spring-damper between the face centre and the load point that touched
  // it, holding the relative orientation of the moment of grasp.
  Eigen::Vector3d force_on_load = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_on_load = Eigen::Vector3d::Zero();
  Eigen::Vector3d load_point = tool.translation();
  const auto spring = [&]() {
    const MagnetSpring params = magnet_spring_for(grip_body);
    load_point = load * anchor_load;
    Eigen::Vector3d load_velocity;
    Eigen::Vector3d load_angular;
    Eigen::Vector3d gripper_velocity;
    Eigen::Vector3d gripper_angular;
    body_point_velocity(*model, *data, grip_body, load_point, load_velocity, load_angular);
    body_point_velocity(*model, *data, index.gripper_body, tool.translation(), gripper_velocity,
                        gripper_angular);
    force_on_load = -params.stiffness_n_per_m * (load_point - tool.translation()) -
                    params.damping_n_s_per_m * (load_velocity - gripper_velocity);
    const Eigen::Matrix3d load_wanted = tool.linear() * rotation_tool_load;
    torque_on_load =
        -params.rotational_stiffness_nm_per_rad * rotation_error(load.linear(), load_wanted) -
        params.rotational_damping_nm_s_per_rad * (load_angular - gripper_angular);
  };

  double current_utilisation = 0.0;
  if (holding) {
    spring();
    const Eigen::Matrix3d to_tool = tool.linear().transpose();
    current_utilisation =
        magnet_utilisation(to_tool * force_on_load, to_tool * torque_on_load, capacity);
  }
  switch (magnet.update(face_in_contact, current_utilisation, dt_s)) {
    case GripAction::Attach:
      holding = true;
      held_body = grip_body;
      anchor_load = load.inverse() * tool.translation();
      rotation_tool_load = tool.linear().transpose() * load.linear();
      spring();
      break;
    case GripAction::Release:
      holding = false;
      held_body = -1;
      break;
    case GripAction::None:
      break;
  }
  utilisation = holding ? magnet.filtered_utilisation() : 0.0;
  if (holding) {
    // Equal and opposite, at the same point, so momentum is conserved.
    add_wrench_at(*data, held_body, force_on_load, torque_on_load, load_point);
    add_wrench_at(*data, index.gripper_body, -force_on_load, -torque_on_load, load_point);
  }
}

void CellPhysics::Impl::record_wrench() {
  // MuJoCo's force/torque sensors: what the flange exerts on the gripper, in the sensor frame,
  // torque about the sensor origin.  The gripper side exerts the opposite on the flange.
  const Eigen::Vector3d force = -vec3(data->sensordata + index.ft_force_address);
  const Eigen::Vector3d torque_sensor = -vec3(data->sensordata + index.ft_torque_address);
  // Tool frame: same axes as the sensor (both sites are unrotated on the gripper body).
  const Eigen::Vector3d tool_offset = vec3(model->site_pos + 3 * index.tool_site);
  Wrench raw;
  raw.force_n = force;
  raw.torque_nm = torque_sensor - tool_offset.cross(force);

  // Static weight of the gripper, as a controller's tool-load data would predict it.
  const Eigen::Matrix3d rotation_world_sensor = site_pose_world(index.ft_site).linear();
  const double gripper_mass = model->body_mass[index.gripper_body];
  const Eigen::Vector3d weight_sensor =
      rotation_world_sensor.transpose() * (gripper_mass * vec3(model->opt.gravity));
  const Eigen::Vector3d com_sensor = vec3(model->body_ipos + 3 * index.gripper_body);
  Wrench weight;
  weight.force_n = weight_sensor;
  weight.torque_nm = (com_sensor - tool_offset).cross(weight_sensor);

  const WrenchNoise& noise = options.wrench_noise;
  for (int i = 0; i < 3; ++i) {
    if (noise.force_stddev_n > 0.0) {
      raw.force_n[i] += noise.force_stddev_n * unit_normal(noise_engine);
    }
    if (noise.torque_stddev_nm > 0.0) {
      raw.torque_nm[i] += noise.torque_stddev_nm * unit_normal(noise_engine);
    }
  }
  wrench_raw = raw;
  wrench_external.force_n = raw.force_n - weight.force_n;
  wrench_external.torque_nm = raw.torque_nm - weight.torque_nm;
}

// ---- CellPhysics ---------------------------------------------------------------------------

CellPhysics::CellPhysics(const CellGeometry& cell, const CellPhysicsOptions& options)
    : impl_(std::make_unique<Impl>(cell, options)) {}

CellPhysics::~CellPhysics() = default;
CellPhysics::CellPhysics(CellPhysics&&) noexcept = default;
CellPhysics& CellPhysics::operator=(CellPhysics&&) noexcept = default;

std::chrono::nanoseconds CellPhysics::sim_time() const {
  return impl_->timestep_ns * static_cast<std::int64_t>(impl_->steps);
}

std::chrono::nanoseconds CellPhysics::timestep() const { return impl_->timestep_ns; }

void CellPhysics::step(std::chrono::nanoseconds duration) {
  if (duration.count() <= 0) {
    return;
  }
  const auto step_ns = impl_->timestep_ns.count();
  impl_->run_steps(static_cast<std::uint64_t>((duration.count() + step_ns / 2) / step_ns));
}

void CellPhysics::advance_to(std::chrono::nanoseconds target) {
  const auto remaining = target - sim_time();
  if (remaining.count() <= 0) {
    return;
  }
  const auto step_ns = impl_->timestep_ns.count();
  impl_->run_steps(static_cast<std::uint64_t>((remaining.count() + step_ns / 2) / step_ns));
}

CommandResult CellPhysics::set_crane_velocity(const Eigen::Vector3d& setpoint_mps) {
  if (!setpoint_mps.allFinite()) {
    return {CommandStatus::RejectedNonFinite, "crane velocity setpoint is not finite", 0};
  }
  if (setpoint_mps.cwiseAbs().maxCoeff() > kMaxCraneSetpointMps) {
    return {CommandStatus::RejectedOutOfRange, "crane velocity setpoint above 10 m/s", 0};
  }
  if (impl_->crane_frozen) {
    return {CommandStatus::Accepted, "crane frozen: held at zero until unfrozen", 0};
  }
  impl_->crane_setpoint_mps = setpoint_mps;
  return {};
}

void CellPhysics::set_crane_frozen(bool frozen) {
  impl_->crane_frozen = frozen;
  impl_->crane_setpoint_mps.setZero();
}

CraneState CellPhysics::crane_state() const {
  const Impl& impl = *impl_;
  const mjData& data = *impl.data;
  const detail::CellModelIndex& index = impl.index;
  CraneState state;
  state.position_m = {data.qpos[index.bridge.qpos], data.qpos[index.trolley.qpos],
                      impl.drum.payout_m()};
  state.velocity_mps = {data.qvel[index.bridge.dof], data.qvel[index.trolley.dof],
                        impl.drum.payout_rate_mps()};
  state.velocity_setpoint_mps =
      impl.crane_frozen ? Eigen::Vector3d::Zero() : impl.crane_setpoint_mps;
  const CraneGeometry& crane = impl.cell.crane;
  state.range_min_m = {crane.bridge_range_m[0], crane.trolley_range_m[0],
                       crane.rope_length_range_m[0]};
  state.range_max_m = {crane.bridge_range_m[1], crane.trolley_range_m[1],
                       crane.rope_length_range_m[1]};
  state.frozen = impl.crane_frozen;
  state.rope_tension_n = impl.rope_tension;
  state.load_mass_estimate_kg = impl.load_mass_estimate;
  state.hook_distance_m = data.qpos[index.rope_length.qpos];
  state.rope_slack = state.hook_distance_m < impl.drum.payout_m();
  state.sway_angle_rad = {data.qpos[index.sway_x.qpos], data.qpos[index.sway_y.qpos]};
  state.sway_rate_rad_per_s = {data.qvel[index.sway_x.dof], data.qvel[index.sway_y.dof]};
  state.position_world_hook_m = vec3(data.xpos + 3 * index.hook_body);
  return state;
}

CommandResult CellPhysics::move_joints(const JointVector& goal_rad, double speed_fraction) {
  return impl_->arm->move_joints(goal_rad, speed_fraction);
}

CommandResult CellPhysics::move_tool(const Eigen::Isometry3d& goal_base_tool,
                                     double speed_fraction) {
  return impl_->arm->move_tool(goal_base_tool, speed_fraction);
}

CommandResult CellPhysics::set_tool_twist(const Twist& twist_base) {
  return impl_->arm->set_twist(twist_base, impl_->now_s());
}

void CellPhysics::stop_robot() { impl_->arm->stop(); }

RobotState CellPhysics::robot_state() const {
  const Impl& impl = *impl_;
  RobotState state;
  state.position_rad = impl.joint_positions();
  state.velocity_rad_per_s = impl.joint_velocities();
  state.torque_nm = impl.joint_torque;
  state.reference_position_rad = impl.arm->reference_position();
  state.reference_velocity_rad_per_s = impl.arm->reference_velocity();
  state.pose_world_base = impl.pose_world_base;
  state.pose_world_flange = impl.site_pose_world(impl.index.flange_site);
  state.pose_world_tool = impl.site_pose_world(impl.index.tool_site);
  const Eigen::Isometry3d pose_base_world = impl.pose_world_base.inverse();
  state.pose_base_flange = pose_base_world * state.pose_world_flange;
  state.pose_base_tool = pose_base_world * state.pose_world_tool;
  mjtNum velocity[6];
  mj_objectVelocity(impl.model.get(), impl.data.get(), mjOBJ_SITE, impl.index.tool_site, velocity,
                    0);
  state.twist_base_tool.angular_rad_per_s = pose_base_world.linear() * vec3(velocity);
  state.twist_base_tool.linear_mps = pose_base_world.linear() * vec3(velocity + 3);
  state.mode = impl.arm->mode();
  state.motion = impl.arm->motion();
  return state;
}

const ArmLimits& CellPhysics::arm_limits() const { return impl_->arm_limits; }

Eigen::Isometry3d CellPhysics::tool_pose_for(const JointVector& q_rad) const {
  return impl_->kinematics->pose_base_tool(q_rad);
}

IkResult CellPhysics::solve_ik(const Eigen::Isometry3d& pose_base_tool,
                               const JointVector* seed) const {
  if (!pose_base_tool.matrix().allFinite() || (seed != nullptr && !seed->allFinite())) {
    return {};
  }
  return impl_->arm->solve_ik(pose_base_tool, seed);
}

void CellPhysics::set_gripper_energized(bool energized) { impl_->magnet.set_energized(energized); }

GripperState CellPhysics::gripper_state() const {
  const Impl& impl = *impl_;
  GripperState state;
  state.energized = impl.magnet.energized();
  state.holding = impl.holding;
  state.in_contact = impl.face_in_contact;
  state.phase = impl.magnet.phase();
  state.holding_force_n = impl.capacity.holding_force_n;
  state.utilisation = impl.utilisation;
  state.slip_count = impl.magnet.slip_count();
  return state;
}

Wrench CellPhysics::wrench_tool() const { return impl_->wrench_raw; }

Wrench CellPhysics::external_wrench_tool() const { return impl_->wrench_external; }

Eigen::Isometry3d CellPhysics::pose_world_load() const {
  return impl_->body_pose_world(impl_->index.load_body);
}

Twist CellPhysics::twist_world_load() const {
  mjtNum velocity[6];
  mj_objectVelocity(impl_->model.get(), impl_->data.get(), mjOBJ_BODY, impl_->index.load_body,
                    velocity, 0);
  Twist twist;
  twist.angular_rad_per_s = vec3(velocity);
  twist.linear_mps = vec3(velocity + 3);
  return twist;
}

std::optional<Eigen::Isometry3d> CellPhysics::pose_world_part() const {
  if (!impl_->cell.part) return std::nullopt;
  return impl_->body_pose_world(impl_->index.part_body);
}

std::optional<Eigen::Isometry3d> CellPhysics::pose_world_part_fixture() const {
  if (!impl_->cell.part) return std::nullopt;
  return impl_->body_pose_world(impl_->index.part_fixture_body);
}

Eigen::Isometry3d CellPhysics::pose_world_target() const {
  return impl_->body_pose_world(impl_->index.target_body);
}

Eigen::Isometry3d CellPhysics::pose_world_robot_base() const { return impl_->pose_world_base; }

const CellGeometry& CellPhysics::geometry() const { return impl_->cell; }

CommandResult CellPhysics::set_gripper_holding_force(double holding_force_n) {
  if (!std::isfinite(holding_force_n)) {
    return {CommandStatus::RejectedNonFinite, "holding force is not finite", 0};
  }
  if (holding_force_n < 0.0) {
    return {CommandStatus::RejectedOutOfRange, "holding force must be >= 0 N", 0};
  }
  impl_->capacity.holding_force_n = holding_force_n;
  return {};
}

CommandResult CellPhysics::set_load_external_force(const Eigen::Vector3d& force_world_n) {
  if (!force_world_n.allFinite()) {
    return {CommandStatus::RejectedNonFinite, "external force is not finite", 0};
  }
  if (force_world_n.norm() > kMaxLoadExternalForceN) {
    return {CommandStatus::RejectedOutOfRange, "external force above 100 kN", 0};
  }
  impl_->load_force_world = force_world_n;
  return {};
}

PhysicsDiagnostics CellPhysics::diagnostics() const {
  const Impl& impl = *impl_;
  PhysicsDiagnostics diagnostics;
  diagnostics.steps = impl.steps;
  for (int i = 0; i < mjNWARNING; ++i) {
    const int count = impl.data->warning[i].number;
    if (count > 0) {
      diagnostics.mujoco_warning_count += count;
      diagnostics.last_mujoco_warning = kWarningNames[i];
    }
  }
  const double wall_s = std::chrono::duration<double>(impl.wall_stepping).count();
  if (wall_s > 0.0) {
    diagnostics.steps_per_second = static_cast<double>(impl.steps) / wall_s;
    diagnostics.measured_real_time_factor = diagnostics.steps_per_second * impl.timestep_s;
  }
  return diagnostics;
}

}  // namespace rigger::sim
