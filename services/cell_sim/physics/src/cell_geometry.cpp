#include "rigger/sim/cell_geometry.hpp"

#include <algorithm>

#include "object_geometry.hpp"
#include "rigger/cell_config/cell_cad.hpp"

namespace rigger::sim {
namespace {

using cell::AttributeReader;
using cell::CellEntity;
using cell::CellFile;

const ObjectGeometry& object_named(const std::vector<ObjectGeometry>& objects, const std::string& id) {
  return *std::find_if(objects.begin(), objects.end(), [&](const ObjectGeometry& object) { return object.id == id; });
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
  robot.calibration_board = entity.calibration_board;
  return robot;
}

GripperGeometry parse_gripper(const CellFile& file) {
  const AttributeReader attributes(file, file.require("gripper", "the gripper of the physics"));
  return {attributes.positive("holding_force_n"), attributes.positive("flange_to_face_m")};
}

// The load: the one object the crane's rope hooks.
LoadGeometry parse_load(const CellFile& file, const std::vector<ObjectGeometry>& objects) {
  const ObjectGeometry* hooked = nullptr;
  for (const ObjectGeometry& object : objects) {
    if (!object.pose_object_rope_attachment) continue;
    if (hooked != nullptr) {
      file.fail(object.pointer + "/features/rope_attachment",
                "one object with a rope attachment (the crane carries one load; \"" + hooked->id + "\" has one)");
    }
    if (object.is_static) {
      file.fail(object.pointer + "/model/static", "false for the object the crane's rope hooks", "true");
    }
    hooked = &object;
  }
  if (hooked == nullptr) {
    file.fail("/entities", "an object with features.rope_attachment (the crane's load)", "none");
  }
  const CellEntity& entity = *file.find(hooked->id);
  LoadGeometry load;
  load.id = hooked->id;
  load.pose_world_load = hooked->pose_world_object;
  load.size_m = hooked->bounds_m().second;
  load.mass_kg = hooked->mass_kg;
  load.pose_load_rope_attachment = *hooked->pose_object_rope_attachment;

  const cell::CadFeatures& features = entity.features;
  if (features.grasp_frames.empty()) {
    file.fail(entity.pointer + "/features/grasp_frames", "at least one grasp frame", "none");
  }
  load.grasp_frames = features.grasp_frames;
  load.approach_waypoints = features.approach_waypoints;
  if (features.insertion) {
    const CellEntity* target = file.find(features.insertion->target);
    if (target == nullptr || target->kind != cell::EntityKind::kObject || !target->model || !target->model->is_static) {
      file.fail(entity.pointer + "/features/insertion/target", "a static object (the fixture the load goes into)",
                "\"" + features.insertion->target + "\"");
    }
    load.pose_target_load_inserted = features.insertion->pose_target_entity;
  }
  return load;
}

// The target: the load's insertion target, or the entity "target".
TargetGeometry parse_target(const CellFile& file, const CellEntity& load, const std::vector<ObjectGeometry>& objects) {
  const std::string id = load.features.insertion ? load.features.insertion->target : std::string("target");
  const CellEntity* entity = file.find(id);
  if (entity == nullptr || entity->kind != cell::EntityKind::kObject) {
    file.fail(load.pointer + "/features/insertion", "the load's insertion target (or an object \"target\")",
              "nothing (missing key)");
  }
  const ObjectGeometry& target = object_named(objects, id);
  return {id, target.pose_world_object, target.bounds_m().second};
}

// The part Pick and Place move ("part") and its table ("part_fixture"), when the cell has both.
std::optional<PartGeometry> parse_part(const CellFile& file, const std::vector<ObjectGeometry>& objects) {
  if (file.find("part") == nullptr || file.find("part_fixture") == nullptr) return std::nullopt;
  const ObjectGeometry& object = object_named(objects, "part");
  const ObjectGeometry& fixture = object_named(objects, "part_fixture");
  return PartGeometry{object.pose_world_object, object.bounds_m().second, object.mass_kg, fixture.pose_world_object,
                      fixture.bounds_m().second};
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

CellGeometry cell_geometry_from(const CellFile& file, const std::filesystem::path& model_dir) {
  return detail::cell_geometry_with_models(file, model_dir, {});
}

CellGeometry detail::cell_geometry_with_models(const CellFile& file, const std::filesystem::path& model_dir,
                                               const std::map<std::string, cad::Model>& read_models) {
  file.require_cad_derived("the physics");
  const std::filesystem::path parent = std::filesystem::path(file.source).parent_path();
  const std::filesystem::path models = !model_dir.empty() ? model_dir : parent.empty() ? "." : parent;
  CellGeometry cell;
  cell.source = file.source;
  cell.crane = parse_crane(file);
  cell.robot = parse_robot(file);
  cell.gripper = parse_gripper(file);
  for (const CellEntity& entity : file.entities) {
    if (entity.kind == cell::EntityKind::kObject) cell.objects.push_back(detail::object_geometry_from(file, entity, models, read_models));
  }
  cell.load = parse_load(file, cell.objects);
  cell.target = parse_target(file, *file.find(cell.load.id), cell.objects);
  cell.part = parse_part(file, cell.objects);
  return cell;
}

CellGeometry parse_cell_geometry(const std::string& json_text, const std::string& source,
                                 const std::filesystem::path& model_dir) {
  return cell::rethrow_as<CellGeometryError>([&] {
    cell::CellFile file = cell::parse_cell_file(json_text, source);
    const std::filesystem::path parent = std::filesystem::path(source).parent_path();
    const std::filesystem::path models = !model_dir.empty() ? model_dir : parent.empty() ? "." : parent;
    const cell::CadDerivation derivation = cell::derive_cad_features(file, models);
    return detail::cell_geometry_with_models(file, models, derivation.read_models);
  });
}

CellGeometry load_cell_geometry(const std::filesystem::path& path) {
  return cell::rethrow_as<CellGeometryError>([&] {
    cell::CadDerivation derivation;
    const CellFile file = cell::load_cell_file_with_cad(path, &derivation);
    return detail::cell_geometry_with_models(file, {}, derivation.read_models);
  });
}

}  // namespace rigger::sim
