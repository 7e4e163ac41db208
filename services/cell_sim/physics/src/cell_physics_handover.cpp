// CellPhysics built anew from a revised cell, continuing where the running one stands (continue_from).
#include <algorithm>
#include <string>

#include "cell_physics_impl.hpp"

namespace rigger::sim {
namespace {

// Two device poses are the same within this (m, and rotation matrix entries): both come from the same cell
// file numbers, so they agree to rounding.
constexpr double kSamePose = 1e-9;

// A joint's share of qpos and qvel.
int qpos_width(int type) {
  return type == mjJNT_FREE ? 7 : type == mjJNT_BALL ? 4 : 1;
}
int dof_width(int type) {
  return type == mjJNT_FREE ? 6 : type == mjJNT_BALL ? 3 : 1;
}

}  // namespace

CommandResult CellPhysics::continue_from(const CellPhysics& running) {
  Impl& now = *impl_;
  const Impl& old = *running.impl_;
  if (old.arm->mode() != RobotMode::Hold || !old.arm->reference_velocity().isZero())
    return {CommandStatus::RejectedHeld, "the robot moves: the model is built anew only while the arm holds still", 0};
  if (old.holding)
    return {CommandStatus::RejectedHeld, "the magnet holds something: the model is built anew only with it empty", 0};
  if (old.cell.load.id != now.cell.load.id)
    return {CommandStatus::RejectedHeld,
            "the crane's load would change from \"" + old.cell.load.id + "\" to \"" + now.cell.load.id + "\"", 0};
  if (!old.pose_world_base.isApprox(now.pose_world_base, kSamePose) ||
      !old.cell.crane.pose_world_crane.isApprox(now.cell.crane.pose_world_crane, kSamePose))
    return {CommandStatus::RejectedOutOfRange, "the robot's base or the crane stands elsewhere in the new cell", 0};

  const mjModel& m = *now.model;
  mjData& d = *now.data;
  const mjModel& om = *old.model;
  const mjData& od = *old.data;
  // Every joint both models name (the devices', the load's swivel, each persisting free object's): MuJoCo's
  // qpos and qvel hold the whole state of a body tree, so this carries the bodies over as they move.
  for (int j = 0; j < m.njnt; ++j) {
    const char* name = mj_id2name(&m, mjOBJ_JOINT, j);
    const int o = name != nullptr ? mj_name2id(&om, mjOBJ_JOINT, name) : -1;
    if (o < 0 || om.jnt_type[o] != m.jnt_type[j]) continue;
    const int type = m.jnt_type[j];
    std::copy_n(od.qpos + om.jnt_qposadr[o], qpos_width(type), d.qpos + m.jnt_qposadr[j]);
    std::copy_n(od.qvel + om.jnt_dofadr[o], dof_width(type), d.qvel + m.jnt_dofadr[j]);
    std::copy_n(od.qacc_warmstart + om.jnt_dofadr[o], dof_width(type), d.qacc_warmstart + m.jnt_dofadr[j]);
  }
  d.time = od.time;
  for (int i = 0; i < mjNWARNING; ++i) d.warning[i] = od.warning[i];

  now.steps = old.steps;
  now.wall_stepping = old.wall_stepping;
  now.bridge = old.bridge;
  now.trolley = old.trolley;
  now.drum = old.drum;
  now.crane_frozen = old.crane_frozen;
  now.crane_setpoint_mps = old.crane_setpoint_mps;
  now.rope_tension = old.rope_tension;
  now.load_mass_estimate = old.load_mass_estimate;
  now.joint_torque = old.joint_torque;
  now.arm->continue_from(*old.arm);
  now.magnet = old.magnet;
  now.capacity = old.capacity;
  now.face_in_contact = old.face_in_contact;
  now.holding = false;
  now.held_body = -1;
  now.held_s = 0.0;
  now.utilisation = 0.0;
  now.load_force_world = old.load_force_world;
  now.noise_engine = old.noise_engine;
  // The step's invariant (mj_step1 has run for the current state), then the sensor as it last read.
  mj_forward(now.model.get(), now.data.get());
  now.wrench_raw = old.wrench_raw;
  now.wrench_external = old.wrench_external;
  return {CommandStatus::Accepted, "", 0};
}

}  // namespace rigger::sim
