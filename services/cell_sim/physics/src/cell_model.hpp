#pragma once
// Internal: owning handles for MuJoCo's model and data, the ids of every named element the
// physics uses, and the step that writes the cell JSON's geometry into the compiled model.

#include <mujoco/mujoco.h>

#include <array>
#include <filesystem>
#include <memory>
#include <vector>

#include "rigger/sim/cell_geometry.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::sim::detail {

struct ModelDeleter {
  void operator()(mjModel* model) const noexcept { mj_deleteModel(model); }
};
struct DataDeleter {
  void operator()(mjData* data) const noexcept { mj_deleteData(data); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// A joint's addresses in qpos and qvel.
struct JointAddress {
  int id = -1;
  int qpos = -1;
  int dof = -1;
};

/// Ids of the model elements the physics reads and drives.
struct CellModelIndex {
  int crane_body = -1;
  int bridge_body = -1;
  int hook_body = -1;
  int load_body = -1;
  int target_body = -1;
  int robot_base_body = -1;
  int gripper_body = -1;
  int part_body = -1;
  int part_fixture_body = -1;

  JointAddress bridge;
  JointAddress trolley;
  JointAddress sway_x;
  JointAddress sway_y;
  JointAddress rope_length;
  JointAddress load_swivel;
  JointAddress part_free;
  std::array<JointAddress, kArmJointCount> arm{};

  int bridge_actuator = -1;
  int trolley_actuator = -1;
  int rope_actuator = -1;
  std::array<int, kArmJointCount> arm_actuator{};

  int load_geom = -1;
  int target_geom = -1;
  int pedestal_geom = -1;
  int gripper_face_geom = -1;
  int gripper_housing_geom = -1;
  int part_geom = -1;
  int part_fixture_geom = -1;

  int flange_site = -1;
  int tool_site = -1;
  int ft_site = -1;
  int load_attachment_site = -1;
  int sheave_site = -1;

  int ft_force_address = -1;  // into sensordata
  int ft_torque_address = -1;
};

/// Loads and compiles the MJCF.  Throws PhysicsModelError with MuJoCo's message.
ModelPtr load_model(const std::filesystem::path& path);

/// Looks up every named element.  Throws PhysicsModelError naming the first missing one.
CellModelIndex index_model(const mjModel& model, const std::filesystem::path& path);

/// Writes the cell geometry into the model (poses, sizes, masses, ranges), then recomputes
/// MuJoCo's derived constants.  Returns the initial qpos: the crane above the load's rope
/// attachment, the load hanging at its JSON pose, the part resting at its JSON pose (or, without a part
/// in the cell, on its fixture far from everything), the arm at `initial_arm_rad`.  (qpos0 stays
/// the model's reference configuration: MuJoCo measures hinge and slide joints from it.)
/// Throws CellGeometryError when the geometry does not fit the crane (e.g. the load hangs outside
/// the bridge's range).
std::vector<mjtNum> apply_cell_geometry(mjModel& model, const CellModelIndex& index,
                                        const CellGeometry& cell,
                                        const JointVector& initial_arm_rad);

/// Position and orientation of a body, site or frame from MuJoCo's arrays.
Eigen::Isometry3d to_isometry(const mjtNum* position, const mjtNum* rotation_matrix);

}  // namespace rigger::sim::detail
