#include "rigger/sim/cell_physics.hpp"

#include <algorithm>
#include <cmath>
#include <new>
#include <vector>

#include "cell_mjcf.hpp"
#include "cell_physics_impl.hpp"
#include "rigger/base/install.hpp"
#include "rigger/sim/iiwa14.hpp"
#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

using Clock = std::chrono::steady_clock;

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

CellPhysics::Impl::Impl(const CellGeometry& cell_geometry,
                        const CellPhysicsOptions& physics_options)
    : cell(cell_geometry),
      options(physics_options),
      model(detail::load_cell_model(physics_options.model_path, cell_geometry)),
      index(detail::index_model(*model, physics_options.model_path, cell_geometry)),
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

std::optional<Eigen::Isometry3d> CellPhysics::pose_world_object(std::string_view id) const {
  for (const detail::ObjectBody& object : impl_->index.objects) {
    if (object.id == id) return impl_->body_pose_world(object.body);
  }
  return std::nullopt;
}

CommandResult CellPhysics::can_move_free_object(std::string_view id, const Eigen::Isometry3d& pose_world_object) const {
  const Impl& impl = *impl_;
  if (!pose_world_object.matrix().allFinite()) return {CommandStatus::RejectedNonFinite, "the pose is not finite", 0};
  const Eigen::Matrix3d rotation = pose_world_object.linear();
  if (!(rotation.transpose() * rotation).isIdentity(1e-6) || rotation.determinant() < 0.0)
    return {CommandStatus::RejectedOutOfRange, "the pose's rotation is not a rotation", 0};
  const auto object = std::find_if(impl.index.objects.begin(), impl.index.objects.end(),
                                   [&](const detail::ObjectBody& o) { return o.id == id; });
  const std::string name(id);
  if (object == impl.index.objects.end()) return {CommandStatus::RejectedNotFree, "no object \"" + name + "\"", 0};
  if (object->body == impl.index.load_body)
    return {CommandStatus::RejectedHeld, "\"" + name + "\" hangs from the crane's rope", 0};
  if (object->is_static || object->free.qpos < 0)
    return {CommandStatus::RejectedNotFree, "\"" + name + "\" is static: it moves only with the model built anew", 0};
  if (impl.holding && impl.held_body == object->body)
    return {CommandStatus::RejectedHeld, "the magnet holds \"" + name + "\"", 0};
  return {CommandStatus::Accepted, "", 0};
}

CommandResult CellPhysics::move_free_object(std::string_view id, const Eigen::Isometry3d& pose_world_object) {
  const CommandResult allowed = can_move_free_object(id, pose_world_object);
  if (!allowed.ok()) return allowed;
  Impl& impl = *impl_;
  const auto object = std::find_if(impl.index.objects.begin(), impl.index.objects.end(),
                                   [&](const detail::ObjectBody& o) { return o.id == id; });
  mjtNum* qpos = impl.data->qpos + object->free.qpos;
  const Eigen::Quaterniond q(pose_world_object.linear());
  for (int i = 0; i < 3; ++i) qpos[i] = pose_world_object.translation()[i];
  qpos[3] = q.w();
  qpos[4] = q.x();
  qpos[5] = q.y();
  qpos[6] = q.z();
  for (int i = 0; i < 6; ++i) impl.data->qvel[object->free.dof + i] = 0.0;
  mj_forward(impl.model.get(), impl.data.get());
  return allowed;
}

std::vector<std::string> CellPhysics::object_bodies() const {
  std::vector<std::string> names;
  for (const detail::ObjectBody& object : impl_->index.objects) {
    names.emplace_back(mj_id2name(impl_->model.get(), mjOBJ_BODY, object.body));
  }
  return names;
}

std::shared_ptr<const mjModel_> CellPhysics::copy_model() const {
  mjModel* copy = mj_copyModel(nullptr, impl_->model.get());
  if (copy == nullptr) throw std::bad_alloc();
  return {copy, [](const mjModel* m) { mj_deleteModel(const_cast<mjModel*>(m)); }};
}

void CellPhysics::copy_kinematic_state(KinematicState& state) const {
  const mjModel& m = *impl_->model;
  const mjData& d = *impl_->data;
  state.qpos.assign(d.qpos, d.qpos + m.nq);
  state.mocap_pos.assign(d.mocap_pos, d.mocap_pos + 3 * m.nmocap);
  state.mocap_quat.assign(d.mocap_quat, d.mocap_quat + 4 * m.nmocap);
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
