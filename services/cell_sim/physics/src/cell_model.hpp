#pragma once
// Internal: owning handles for MuJoCo's model and data, the ids of every named element the
// physics uses, and the step that writes the cell JSON's geometry into the compiled model.

#include <mujoco/mujoco.h>

#include <array>
#include <filesystem>
#include <memory>
#include <string>
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

/// The body generated for an object entity.
struct ObjectBody {
  std::string id;
  int body = -1;
  bool is_static = false;
  JointAddress free;  ///< its free joint (free objects other than the load)
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
  int part_body = -1;          ///< the entity "part", or -1
  int part_fixture_body = -1;  ///< the entity "part_fixture", or -1
  std::vector<ObjectBody> objects;  ///< every object entity's body, in file order
  /// Per geom: it belongs to a free object (the magnet may grip it).
  std::vector<bool> free_object_geom;

  JointAddress bridge;
  JointAddress trolley;
  JointAddress sway_x;
  JointAddress sway_y;
  JointAddress rope_length;
  JointAddress load_swivel;
  std::array<JointAddress, kArmJointCount> arm{};

  int bridge_actuator = -1;
  int trolley_actuator = -1;
  int rope_actuator = -1;
  std::array<int, kArmJointCount> arm_actuator{};

  int pedestal_geom = -1;
  int gripper_face_geom = -1;
  int gripper_housing_geom = -1;

  int flange_site = -1;
  int tool_site = -1;
  int ft_site = -1;
  int load_attachment_site = -1;
  int sheave_site = -1;

  int ft_force_address = -1;  // into sensordata
  int ft_torque_address = -1;
};

/// Looks up every named element, the devices' and the cell's objects'.  Throws PhysicsModelError naming
/// the first missing one.
CellModelIndex index_model(const mjModel& model, const std::filesystem::path& path, const CellGeometry& cell);

/// Writes the devices' geometry into the model (crane pose and ranges, robot base, gripper), then
/// recomputes MuJoCo's derived constants (the objects were generated into the model).  Returns the initial
/// qpos: the crane above the load's rope attachment, the load hanging at its JSON pose, every free object
/// at its JSON pose, the arm at `initial_arm_rad`.  (qpos0 stays
/// the model's reference configuration: MuJoCo measures hinge and slide joints from it.)
/// Throws CellGeometryError when the geometry does not fit the crane (e.g. the load hangs outside
/// the bridge's range).
std::vector<mjtNum> apply_cell_geometry(mjModel& model, const CellModelIndex& index,
                                        const CellGeometry& cell,
                                        const JointVector& initial_arm_rad);

/// Position and orientation of a body, site or frame from MuJoCo's arrays.
Eigen::Isometry3d to_isometry(const mjtNum* position, const mjtNum* rotation_matrix);

}  // namespace rigger::sim::detail
