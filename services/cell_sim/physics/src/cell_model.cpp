#include "cell_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <sstream>
#include <string>

namespace rigger::sim::detail {
namespace {

constexpr std::array<const char*, kArmJointCount> kArmJointNames = {
    "iiwa_a1", "iiwa_a2", "iiwa_a3", "iiwa_a4", "iiwa_a5", "iiwa_a6", "iiwa_a7"};
constexpr std::array<const char*, kArmJointCount> kArmActuatorNames = {
    "iiwa_a1_motor", "iiwa_a2_motor", "iiwa_a3_motor", "iiwa_a4_motor",
    "iiwa_a5_motor", "iiwa_a6_motor", "iiwa_a7_motor"};

// Room kept between the geometry's axis ranges and the hard end stops (m).
constexpr double kEndStopOvertravelM = 0.05;

class Lookup {
 public:
  Lookup(const mjModel& model, const std::filesystem::path& path) : model_(model), path_(path) {}

  int id(mjtObj type, const char* name, const char* kind) const {
    const int found = mj_name2id(&model_, type, name);
    if (found < 0) {
      throw PhysicsModelError(path_.string() + ": the model has no " + kind + " named '" + name +
                              "' (required by the cell physics)");
    }
    return found;
  }

  JointAddress joint(const char* name, int expected_type) const {
    JointAddress address;
    address.id = id(mjOBJ_JOINT, name, "joint");
    if (model_.jnt_type[address.id] != expected_type) {
      throw PhysicsModelError(path_.string() + ": joint '" + name + "' has the wrong type");
    }
    address.qpos = model_.jnt_qposadr[address.id];
    address.dof = model_.jnt_dofadr[address.id];
    return address;
  }

  int sensor_address(const char* name, int expected_type) const {
    const int sensor = id(mjOBJ_SENSOR, name, "sensor");
    if (model_.sensor_type[sensor] != expected_type || model_.sensor_dim[sensor] != 3) {
      throw PhysicsModelError(path_.string() + ": sensor '" + name + "' has the wrong type");
    }
    return model_.sensor_adr[sensor];
  }

 private:
  const mjModel& model_;
  const std::filesystem::path& path_;
};

void set_body_pose(mjModel& model, int body, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond quaternion(pose.linear());
  for (int i = 0; i < 3; ++i) {
    model.body_pos[3 * body + i] = pose.translation()[i];
  }
  model.body_quat[4 * body + 0] = quaternion.w();
  model.body_quat[4 * body + 1] = quaternion.x();
  model.body_quat[4 * body + 2] = quaternion.y();
  model.body_quat[4 * body + 3] = quaternion.z();
}

void set_box_geom(mjModel& model, int geom, const Eigen::Vector3d& full_size_m,
                  const Eigen::Vector3d& position_m) {
  const Eigen::Vector3d half = 0.5 * full_size_m;
  for (int i = 0; i < 3; ++i) {
    model.geom_size[3 * geom + i] = half[i];
    model.geom_pos[3 * geom + i] = position_m[i];
  }
  // The broad phase culls with the bounding radius: it must follow the size.
  model.geom_rbound[geom] = half.norm();
}

void set_range(mjModel& model, const JointAddress& joint, double low, double high) {
  model.jnt_range[2 * joint.id + 0] = low;
  model.jnt_range[2 * joint.id + 1] = high;
}

std::string format_range(const Eigen::Vector2d& range) {
  std::ostringstream text;
  text << "[" << range[0] << ", " << range[1] << "]";
  return text.str();
}

}  // namespace

CellModelIndex index_model(const mjModel& model, const std::filesystem::path& path, const CellGeometry& cell) {
  const Lookup lookup(model, path);
  CellModelIndex index;
  index.crane_body = lookup.id(mjOBJ_BODY, "crane", "body");
  index.bridge_body = lookup.id(mjOBJ_BODY, "crane_bridge", "body");
  index.hook_body = lookup.id(mjOBJ_BODY, "crane_hook", "body");
  index.free_object_geom.assign(static_cast<std::size_t>(model.ngeom), false);
  for (const ObjectGeometry& object : cell.objects) {
    ObjectBody body{object.id, lookup.id(mjOBJ_BODY, object.id.c_str(), "body"), object.is_static, {}};
    if (!object.is_static && object.id != cell.load.id) {
      body.free = lookup.joint((object.id + "_free").c_str(), mjJNT_FREE);
    }
    for (int geom = 0; geom < model.ngeom; ++geom) {
      if (model.geom_bodyid[geom] == body.body && !object.is_static) {
        index.free_object_geom[static_cast<std::size_t>(geom)] = true;
      }
    }
    if (object.id == cell.load.id) index.load_body = body.body;
    if (object.id == cell.target.id) index.target_body = body.body;
    if (object.id == "part") index.part_body = body.body;
    if (object.id == "part_fixture") index.part_fixture_body = body.body;
    index.objects.push_back(std::move(body));
  }
  index.robot_base_body = lookup.id(mjOBJ_BODY, "robot_base", "body");
  index.gripper_body = lookup.id(mjOBJ_BODY, "gripper", "body");

  index.bridge = lookup.joint("crane_bridge_x", mjJNT_SLIDE);
  index.trolley = lookup.joint("crane_trolley_y", mjJNT_SLIDE);
  index.sway_x = lookup.joint("crane_sway_x", mjJNT_HINGE);
  index.sway_y = lookup.joint("crane_sway_y", mjJNT_HINGE);
  index.rope_length = lookup.joint("crane_rope_length", mjJNT_SLIDE);
  index.load_swivel = lookup.joint((cell.load.id + "_swivel").c_str(), mjJNT_BALL);
  for (int j = 0; j < kArmJointCount; ++j) {
    index.arm[static_cast<std::size_t>(j)] =
        lookup.joint(kArmJointNames[static_cast<std::size_t>(j)], mjJNT_HINGE);
    index.arm_actuator[static_cast<std::size_t>(j)] =
        lookup.id(mjOBJ_ACTUATOR, kArmActuatorNames[static_cast<std::size_t>(j)], "actuator");
  }

  index.bridge_actuator = lookup.id(mjOBJ_ACTUATOR, "crane_bridge_drive", "actuator");
  index.trolley_actuator = lookup.id(mjOBJ_ACTUATOR, "crane_trolley_drive", "actuator");
  index.rope_actuator = lookup.id(mjOBJ_ACTUATOR, "crane_rope", "actuator");

  index.pedestal_geom = lookup.id(mjOBJ_GEOM, "robot_pedestal", "geom");
  index.gripper_face_geom = lookup.id(mjOBJ_GEOM, "gripper_face", "geom");
  index.gripper_housing_geom = lookup.id(mjOBJ_GEOM, "gripper_housing", "geom");
  for (const int geom : {index.pedestal_geom, index.gripper_face_geom}) {
    if (model.geom_type[geom] != mjGEOM_BOX) {
      throw PhysicsModelError(path.string() + ": geom '" + mj_id2name(&model, mjOBJ_GEOM, geom) +
                              "' must be a box");
    }
  }

  index.flange_site = lookup.id(mjOBJ_SITE, "flange", "site");
  index.tool_site = lookup.id(mjOBJ_SITE, "tool", "site");
  index.ft_site = lookup.id(mjOBJ_SITE, "ft_sensor", "site");
  index.load_attachment_site = lookup.id(mjOBJ_SITE, (cell.load.id + "_rope_attachment").c_str(), "site");
  index.sheave_site = lookup.id(mjOBJ_SITE, "crane_sheave", "site");

  index.ft_force_address = lookup.sensor_address("ft_force", mjSENS_FORCE);
  index.ft_torque_address = lookup.sensor_address("ft_torque", mjSENS_TORQUE);

  // The F/T sensor measures the force between the gripper body and its parent (the flange).
  if (model.site_bodyid[index.ft_site] != index.gripper_body ||
      model.site_bodyid[index.tool_site] != index.gripper_body ||
      model.geom_bodyid[index.gripper_face_geom] != index.gripper_body) {
    throw PhysicsModelError(path.string() +
                            ": sites 'ft_sensor', 'tool' and geom 'gripper_face' must be on body "
                            "'gripper'");
  }
  return index;
}

Eigen::Isometry3d to_isometry(const mjtNum* position, const mjtNum* rotation_matrix) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // MuJoCo stores 3x3 matrices row-major.
  pose.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation_matrix);
  pose.translation() = Eigen::Map<const Eigen::Vector3d>(position);
  return pose;
}

std::vector<mjtNum> apply_cell_geometry(mjModel& model, const CellModelIndex& index,
                                        const CellGeometry& cell,
                                        const JointVector& initial_arm_rad) {
  const std::string& source = cell.source;
  const CraneGeometry& crane = cell.crane;

  // Crane: frame, rail height, end stops just outside the axis ranges.
  set_body_pose(model, index.crane_body, crane.pose_world_crane);
  model.body_pos[3 * index.bridge_body + 2] = crane.rail_height_m;
  set_range(model, index.bridge, crane.bridge_range_m[0] - kEndStopOvertravelM,
            crane.bridge_range_m[1] + kEndStopOvertravelM);
  set_range(model, index.trolley, crane.trolley_range_m[0] - kEndStopOvertravelM,
            crane.trolley_range_m[1] + kEndStopOvertravelM);
  // The hook may come up to the trolley and down to (nearly) the floor; the drum's range is
  // enforced by the drum, a slack rope lets the hook go lower.
  set_range(model, index.rope_length, std::min(0.3, 0.5 * crane.rope_length_range_m[0]),
            crane.rail_height_m - 0.02);

  const LoadGeometry& load = cell.load;
  const Eigen::Vector3d attachment = load.pose_load_rope_attachment.translation();

  // Robot base on a pedestal reaching down to the floor.
  set_body_pose(model, index.robot_base_body, cell.robot.pose_world_base);
  const double base_height = std::max(0.002, cell.robot.pose_world_base.translation().z());
  set_box_geom(model, index.pedestal_geom, Eigen::Vector3d(0.4, 0.4, base_height),
               Eigen::Vector3d(0.0, 0.0, -0.5 * base_height));

  // Gripper: the face sits flange_to_face from the flange.
  const double face = cell.gripper.flange_to_face_m;
  if (face < 0.05 || face > 0.5) {
    throw CellGeometryError(source + ": gripper flange_to_face_m = " + std::to_string(face) +
                            ": expected 0.05 .. 0.5 m (the modelled magnet gripper)");
  }
  const double plate_half_thickness = model.geom_size[3 * index.gripper_face_geom + 2];
  model.site_pos[3 * index.tool_site + 2] = face;
  model.geom_pos[3 * index.gripper_face_geom + 2] = face - plate_half_thickness;
  const double housing_half_length = 0.5 * (face - 2.0 * plate_half_thickness);
  model.geom_size[3 * index.gripper_housing_geom + 1] = housing_half_length;
  model.geom_pos[3 * index.gripper_housing_geom + 2] = housing_half_length;

  // Initial configuration: the crane stands above the rope attachment and the load hangs still.
  const Eigen::Isometry3d pose_crane_load = crane.pose_world_crane.inverse() * load.pose_world_load;
  const Eigen::Vector3d attachment_crane = pose_crane_load * attachment;
  const double rope_length = crane.rail_height_m - attachment_crane.z();
  const auto check_axis = [&](double value, const Eigen::Vector2d& range, const char* what) {
    if (value < range[0] || value > range[1]) {
      std::ostringstream text;
      text << source << ": load pose: the rope attachment needs the crane " << what << " at "
           << value << " m, outside its range " << format_range(range);
      throw CellGeometryError(text.str());
    }
  };
  check_axis(attachment_crane.x(), crane.bridge_range_m, "bridge (bridge_range_m)");
  check_axis(attachment_crane.y(), crane.trolley_range_m, "trolley (trolley_range_m)");
  check_axis(rope_length, crane.rope_length_range_m, "rope length (rope_length_range_m)");
  std::vector<mjtNum> qpos(model.qpos0, model.qpos0 + model.nq);
  qpos[static_cast<std::size_t>(index.bridge.qpos)] = attachment_crane.x();
  qpos[static_cast<std::size_t>(index.trolley.qpos)] = attachment_crane.y();
  qpos[static_cast<std::size_t>(index.sway_x.qpos)] = 0.0;
  qpos[static_cast<std::size_t>(index.sway_y.qpos)] = 0.0;
  qpos[static_cast<std::size_t>(index.rope_length.qpos)] = rope_length;
  const Eigen::Quaterniond swivel(pose_crane_load.linear());
  const std::size_t swivel_address = static_cast<std::size_t>(index.load_swivel.qpos);
  qpos[swivel_address + 0] = swivel.w();
  qpos[swivel_address + 1] = swivel.x();
  qpos[swivel_address + 2] = swivel.y();
  qpos[swivel_address + 3] = swivel.z();
  for (int j = 0; j < kArmJointCount; ++j) {
    qpos[static_cast<std::size_t>(index.arm[static_cast<std::size_t>(j)].qpos)] =
        initial_arm_rad[j];
  }
  // A free joint's qpos is the body's world position and orientation.
  for (const ObjectBody& body : index.objects) {
    if (body.free.id < 0) continue;
    const auto object = std::find_if(cell.objects.begin(), cell.objects.end(),
                                     [&](const ObjectGeometry& candidate) { return candidate.id == body.id; });
    const Eigen::Isometry3d& pose = object->pose_world_object;
    const Eigen::Quaterniond rotation(pose.linear());
    const std::size_t address = static_cast<std::size_t>(body.free.qpos);
    for (std::size_t i = 0; i < 3; ++i) qpos[address + i] = pose.translation()[static_cast<Eigen::Index>(i)];
    qpos[address + 3] = rotation.w();
    qpos[address + 4] = rotation.x();
    qpos[address + 5] = rotation.y();
    qpos[address + 6] = rotation.z();
  }

  // Masses, inertias and poses changed: recompute subtree masses, dof_M0, inverse weights...
  DataPtr scratch(mj_makeData(&model));
  if (!scratch) {
    throw PhysicsModelError("MuJoCo could not allocate data for the model");
  }
  mj_setConst(&model, scratch.get());
  return qpos;
}

}  // namespace rigger::sim::detail
