#include "rigger/sim/cell_geometry.hpp"

#include "rigger/cell_config/cell_cad.hpp"

namespace rigger::sim {
namespace {

using cell::AttributeReader;
using cell::CellEntity;
using cell::CellFile;

// The box model of an entity (the reader has checked its shape and extents when present).
const cell::ObjectModel& require_model(const CellFile& file, const CellEntity& entity) {
  if (!entity.model)
    file.fail(entity.pointer + "/model", "the box model of \"" + entity.id + "\"", "nothing (missing key)");
  return *entity.model;
}

CraneGeometry parse_crane(const CellFile& file) {
  const CellEntity& entity = file.require("crane", "the crane of the physics");
  const AttributeReader attributes(file, entity);
  CraneGeometry crane;
  crane.pose_world_crane = file.pose_root_entity(entity.id);
  crane.rail_height_m = attributes.positive("rail_height_m");
  crane.bridge_range_m = attributes.range("bridge_range_m");
  crane.trolley_range_m = attributes.range("trolley_range_m");
  crane.rope_length_range_m = attributes.range("rope_length_range_m");
  if (crane.rope_length_range_m[0] <= 0.0 || crane.rope_length_range_m[1] >= crane.rail_height_m) {
    file.fail(attributes.pointer("rope_length_range_m"),
              "0 < min < max < rail_height_m (the hook must stay above the floor)");
  }
  crane.max_speed_mps = attributes.positive3("max_speed_mps");
  crane.max_accel_mps2 = attributes.positive3("max_accel_mps2");
  crane.rated_load_kg = attributes.positive("rated_load_kg");
  return crane;
}

RobotGeometry parse_robot(const CellFile& file) {
  const CellEntity& entity = file.require("robot", "the arm of the physics");
  const AttributeReader attributes(file, entity);
  RobotGeometry robot;
  robot.pose_world_base = file.pose_root_entity(entity.id);
  robot.model = attributes.text("model");
  if (robot.model != "kuka_lbr_iiwa_14_r820") {
    file.fail(attributes.pointer("model"), "\"kuka_lbr_iiwa_14_r820\" (the only arm modelled)",
              "\"" + robot.model + "\"");
  }
  robot.tool_length_m = attributes.positive("tool_length_m");
  return robot;
}

GripperGeometry parse_gripper(const CellFile& file) {
  const AttributeReader attributes(file, file.require("gripper", "the gripper of the physics"));
  return {attributes.positive("holding_force_n"), attributes.positive("flange_to_face_m")};
}

LoadGeometry parse_load(const CellFile& file) {
  const CellEntity& entity = file.require("load", "the load of the physics");
  LoadGeometry load;
  load.pose_world_load = file.pose_root_entity(entity.id);
  const cell::ObjectModel& model = require_model(file, entity);
  load.size_m = model.size_m;
  if (!model.mass_kg) file.fail(entity.pointer + "/model/mass_kg", "the load's mass in kg", "nothing (missing key)");
  load.mass_kg = *model.mass_kg;

  const cell::CadFeatures& features = entity.features;
  if (!features.rope_attachment) {
    file.fail(entity.pointer + "/features/rope_attachment", "the pose where the rope hooks", "nothing (missing key)");
  }
  load.pose_load_rope_attachment = *features.rope_attachment;
  if (features.grasp_frames.empty()) {
    file.fail(entity.pointer + "/features/grasp_frames", "at least one grasp frame", "none");
  }
  load.grasp_frames = features.grasp_frames;
  load.approach_waypoints = features.approach_waypoints;
  if (features.insertion) {
    if (features.insertion->target != "target") {
      file.fail(entity.pointer + "/features/insertion/target", "\"target\" (the modelled fixture)",
                "\"" + features.insertion->target + "\"");
    }
    load.pose_target_load_inserted = features.insertion->pose_target_entity;
  }
  return load;
}

TargetGeometry parse_target(const CellFile& file) {
  const CellEntity& entity = file.require("target", "the fixture of the physics");
  return {file.pose_root_entity(entity.id), require_model(file, entity).size_m};
}

std::optional<PartGeometry> parse_part(const CellFile& file) {
  const CellEntity* entity = file.find("part");
  if (entity == nullptr) return std::nullopt;
  PartGeometry part;
  part.pose_world_part = file.pose_root_entity(entity->id);
  const cell::ObjectModel& model = require_model(file, *entity);
  part.size_m = model.size_m;
  if (!model.mass_kg) file.fail(entity->pointer + "/model/mass_kg", "the part's mass in kg", "nothing (missing key)");
  part.mass_kg = *model.mass_kg;
  const CellEntity& fixture = file.require("part_fixture", "the table the part sits on");
  part.pose_world_fixture = file.pose_root_entity(fixture.id);
  part.fixture_size_m = require_model(file, fixture).size_m;
  return part;
}

}  // namespace

std::optional<Eigen::Isometry3d> CellGeometry::grasp_frame(const std::string& id) const {
  for (const NamedPose& frame : load.grasp_frames) {
    if (frame.id == id) {
      return frame.pose_entity_feature;
    }
  }
  return std::nullopt;
}

CellGeometry cell_geometry_from(const CellFile& file) {
  file.require_cad_derived("the physics");
  CellGeometry cell;
  cell.source = file.source;
  cell.crane = parse_crane(file);
  cell.robot = parse_robot(file);
  cell.gripper = parse_gripper(file);
  cell.load = parse_load(file);
  cell.target = parse_target(file);
  cell.part = parse_part(file);
  return cell;
}

CellGeometry parse_cell_geometry(const std::string& json_text, const std::string& source,
                                 const std::filesystem::path& model_dir) {
  return cell::rethrow_as<CellGeometryError>([&] {
    cell::CellFile file = cell::parse_cell_file(json_text, source);
    const std::filesystem::path parent = std::filesystem::path(source).parent_path();
    cell::derive_cad_features(file, !model_dir.empty() ? model_dir : parent.empty() ? "." : parent);
    return cell_geometry_from(file);
  });
}

CellGeometry load_cell_geometry(const std::filesystem::path& path) {
  return cell::rethrow_as<CellGeometryError>([&] { return cell_geometry_from(cell::load_cell_file_with_cad(path)); });
}

}  // namespace rigger::sim
