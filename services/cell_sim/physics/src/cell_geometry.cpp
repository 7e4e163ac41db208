#include "rigger/sim/cell_geometry.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

using nlohmann::json;

constexpr double kDegToRad = M_PI / 180.0;

// Reads values out of the parsed document; every failure names source, JSON pointer, expectation.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& expectation) const {
    throw CellGeometryError(source_ + ": " + (pointer.empty() ? "/" : pointer) + ": " +
                            expectation);
  }

  const json& member(const json& object, const std::string& key, const std::string& pointer) const {
    if (!object.is_object()) {
      fail(pointer, "expected an object");
    }
    const auto it = object.find(key);
    if (it == object.end()) {
      fail(pointer + "/" + key, "missing (required)");
    }
    return *it;
  }

  double number(const json& value, const std::string& pointer) const {
    if (!value.is_number()) {
      fail(pointer, "expected a number");
    }
    const double number_value = value.get<double>();
    if (!std::isfinite(number_value)) {
      fail(pointer, "expected a finite number");
    }
    return number_value;
  }

  double positive(const json& value, const std::string& pointer) const {
    const double number_value = number(value, pointer);
    if (number_value <= 0.0) {
      fail(pointer, "expected a positive number, got " + std::to_string(number_value));
    }
    return number_value;
  }

  std::string string(const json& value, const std::string& pointer) const {
    if (!value.is_string()) {
      fail(pointer, "expected a string");
    }
    return value.get<std::string>();
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const json& value, const std::string& pointer,
                                     bool must_be_positive = false) const {
    if (!value.is_array() || value.size() != static_cast<std::size_t>(N)) {
      fail(pointer, "expected an array of " + std::to_string(N) + " numbers");
    }
    Eigen::Matrix<double, N, 1> result;
    for (int i = 0; i < N; ++i) {
      const std::string element_pointer = pointer + "/" + std::to_string(i);
      result[i] = must_be_positive ? positive(value[static_cast<std::size_t>(i)], element_pointer)
                                   : number(value[static_cast<std::size_t>(i)], element_pointer);
    }
    return result;
  }

  Eigen::Vector2d range(const json& value, const std::string& pointer) const {
    const Eigen::Vector2d result = vector<2>(value, pointer);
    if (!(result[0] < result[1])) {
      fail(pointer, "expected [min, max] with min < max");
    }
    return result;
  }

  Eigen::Isometry3d pose(const json& value, const std::string& pointer) const {
    const Eigen::Vector3d position =
        vector<3>(member(value, "position_m", pointer), pointer + "/position_m");
    const Eigen::Vector3d rpy_deg =
        vector<3>(member(value, "rpy_deg", pointer), pointer + "/rpy_deg");
    return pose_from_position_rpy(position, rpy_deg * kDegToRad);
  }

  std::vector<NamedPose> named_poses(const json& value, const std::string& pointer) const {
    if (!value.is_array()) {
      fail(pointer, "expected an array of {id, pose}");
    }
    std::vector<NamedPose> result;
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string item_pointer = pointer + "/" + std::to_string(i);
      NamedPose named;
      named.id = string(member(value[i], "id", item_pointer), item_pointer + "/id");
      named.pose = pose(member(value[i], "pose", item_pointer), item_pointer + "/pose");
      result.push_back(std::move(named));
    }
    return result;
  }

 private:
  std::string source_;
};

// Entities by id, with their JSON pointer, for parent-chain resolution.
class EntityTable {
 public:
  EntityTable(const json& document, const Reader& reader) : reader_(reader) {
    const json& entities = reader.member(document, "entities", "");
    if (!entities.is_array()) {
      reader.fail("/entities", "expected an array of entities");
    }
    for (std::size_t i = 0; i < entities.size(); ++i) {
      const std::string pointer = "/entities/" + std::to_string(i);
      const std::string id =
          reader.string(reader.member(entities[i], "id", pointer), pointer + "/id");
      if (!by_id_.emplace(id, Entry{&entities[i], pointer}).second) {
        reader.fail(pointer + "/id", "duplicate entity id '" + id + "'");
      }
    }
  }

  const json& get(const std::string& id) const { return *entry(id).value; }
  const std::string& pointer(const std::string& id) const { return entry(id).pointer; }

  // Pose of the entity in the world, composing parent poses (an entity without "pose" sits at
  // its parent's origin).
  Eigen::Isometry3d pose_world(const std::string& id) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    std::string current = id;
    for (std::size_t depth = 0; current != "world"; ++depth) {
      if (depth > by_id_.size()) {
        reader_.fail(pointer(id) + "/parent", "parent chain does not reach 'world' (cycle)");
      }
      const Entry& current_entry = entry(current);
      const json& value = *current_entry.value;
      if (value.contains("pose")) {
        pose = reader_.pose(value["pose"], current_entry.pointer + "/pose") * pose;
      }
      if (!value.contains("parent")) {
        if (value.value("kind", "") == "frame") {
          break;
        }
        reader_.fail(current_entry.pointer + "/parent", "missing (required)");
      }
      current = reader_.string(value["parent"], current_entry.pointer + "/parent");
    }
    return pose;
  }

 private:
  struct Entry {
    const json* value;
    std::string pointer;
  };

  const Entry& entry(const std::string& id) const {
    const auto it = by_id_.find(id);
    if (it == by_id_.end()) {
      reader_.fail("/entities", "expected an entity with id '" + id + "'");
    }
    return it->second;
  }

  const Reader& reader_;
  std::map<std::string, Entry> by_id_;
};

// The full edge lengths of an entity whose model is a box.
Eigen::Vector3d box_size(const json& entity, const std::string& pointer, const Reader& reader) {
  const std::string model_pointer = pointer + "/model";
  const json& model = reader.member(entity, "model", pointer);
  if (reader.string(reader.member(model, "shape", model_pointer), model_pointer + "/shape") !=
      "box") {
    reader.fail(model_pointer + "/shape", "expected \"box\"");
  }
  return reader.vector<3>(reader.member(model, "size_m", model_pointer), model_pointer + "/size_m",
                          true);
}

CraneGeometry parse_crane(const EntityTable& table, const Reader& reader) {
  const std::string pointer = table.pointer("crane") + "/attributes";
  const json& attributes = reader.member(table.get("crane"), "attributes", table.pointer("crane"));
  CraneGeometry crane;
  crane.pose_world_crane = table.pose_world("crane");
  crane.rail_height_m = reader.positive(reader.member(attributes, "rail_height_m", pointer),
                                        pointer + "/rail_height_m");
  crane.bridge_range_m = reader.range(reader.member(attributes, "bridge_range_m", pointer),
                                      pointer + "/bridge_range_m");
  crane.trolley_range_m = reader.range(reader.member(attributes, "trolley_range_m", pointer),
                                       pointer + "/trolley_range_m");
  crane.rope_length_range_m = reader.range(
      reader.member(attributes, "rope_length_range_m", pointer), pointer + "/rope_length_range_m");
  if (crane.rope_length_range_m[0] <= 0.0 || crane.rope_length_range_m[1] >= crane.rail_height_m) {
    reader.fail(pointer + "/rope_length_range_m",
                "expected 0 < min < max < rail_height_m (the hook must stay above the floor)");
  }
  crane.max_speed_mps = reader.vector<3>(reader.member(attributes, "max_speed_mps", pointer),
                                         pointer + "/max_speed_mps", true);
  crane.max_accel_mps2 = reader.vector<3>(reader.member(attributes, "max_accel_mps2", pointer),
                                          pointer + "/max_accel_mps2", true);
  crane.rated_load_kg = reader.positive(reader.member(attributes, "rated_load_kg", pointer),
                                        pointer + "/rated_load_kg");
  return crane;
}

RobotGeometry parse_robot(const EntityTable& table, const Reader& reader) {
  const std::string pointer = table.pointer("robot") + "/attributes";
  const json& attributes = reader.member(table.get("robot"), "attributes", table.pointer("robot"));
  RobotGeometry robot;
  robot.pose_world_base = table.pose_world("robot");
  robot.model = reader.string(reader.member(attributes, "model", pointer), pointer + "/model");
  if (robot.model != "kuka_lbr_iiwa_14_r820") {
    reader.fail(pointer + "/model", "expected \"kuka_lbr_iiwa_14_r820\" (the only arm modelled)");
  }
  robot.tool_length_m = reader.positive(reader.member(attributes, "tool_length_m", pointer),
                                        pointer + "/tool_length_m");
  return robot;
}

GripperGeometry parse_gripper(const EntityTable& table, const Reader& reader) {
  const std::string pointer = table.pointer("gripper") + "/attributes";
  const json& attributes =
      reader.member(table.get("gripper"), "attributes", table.pointer("gripper"));
  GripperGeometry gripper;
  gripper.holding_force_n = reader.positive(reader.member(attributes, "holding_force_n", pointer),
                                            pointer + "/holding_force_n");
  gripper.flange_to_face_m = reader.positive(reader.member(attributes, "flange_to_face_m", pointer),
                                             pointer + "/flange_to_face_m");
  return gripper;
}

LoadGeometry parse_load(const EntityTable& table, const Reader& reader) {
  const std::string pointer = table.pointer("load");
  const json& load_json = table.get("load");
  LoadGeometry load;
  load.pose_world_load = table.pose_world("load");

  load.size_m = box_size(load_json, pointer, reader);
  const json& model = reader.member(load_json, "model", pointer);
  load.mass_kg = reader.positive(reader.member(model, "mass_kg", pointer + "/model"),
                                 pointer + "/model/mass_kg");

  const std::string features_pointer = pointer + "/features";
  const json& features = reader.member(load_json, "features", pointer);
  load.pose_load_rope_attachment =
      reader.pose(reader.member(features, "rope_attachment", features_pointer),
                  features_pointer + "/rope_attachment");
  load.grasp_frames = reader.named_poses(reader.member(features, "grasp_frames", features_pointer),
                                         features_pointer + "/grasp_frames");
  if (features.contains("approach_waypoints")) {
    load.approach_waypoints = reader.named_poses(features["approach_waypoints"],
                                                 features_pointer + "/approach_waypoints");
  }
  if (features.contains("insertion")) {
    const std::string insertion_pointer = features_pointer + "/insertion";
    const json& insertion = features["insertion"];
    const std::string target = reader.string(reader.member(insertion, "target", insertion_pointer),
                                             insertion_pointer + "/target");
    if (target != "target") {
      reader.fail(insertion_pointer + "/target", "expected \"target\" (the modelled fixture)");
    }
    load.pose_target_load_inserted =
        reader.pose(reader.member(insertion, "pose_in_target", insertion_pointer),
                    insertion_pointer + "/pose_in_target");
  }
  return load;
}

TargetGeometry parse_target(const EntityTable& table, const Reader& reader) {
  const std::string pointer = table.pointer("target");
  const json& target_json = table.get("target");
  TargetGeometry target;
  target.pose_world_target = table.pose_world("target");
  target.size_m = box_size(target_json, pointer, reader);
  return target;
}

}  // namespace

std::optional<Eigen::Isometry3d> CellGeometry::grasp_frame(const std::string& id) const {
  for (const NamedPose& frame : load.grasp_frames) {
    if (frame.id == id) {
      return frame.pose;
    }
  }
  return std::nullopt;
}

CellGeometry parse_cell_geometry(const std::string& json_text, const std::string& source) {
  const Reader reader(source);
  json document;
  try {
    document = json::parse(json_text);
  } catch (const json::parse_error& error) {
    throw CellGeometryError(source + ": not valid JSON: " + error.what());
  }
  const EntityTable table(document, reader);
  CellGeometry cell;
  cell.source = source;
  cell.crane = parse_crane(table, reader);
  cell.robot = parse_robot(table, reader);
  cell.gripper = parse_gripper(table, reader);
  cell.load = parse_load(table, reader);
  cell.target = parse_target(table, reader);
  return cell;
}

CellGeometry load_cell_geometry(const std::filesystem::path& path) {
  std::ifstream stream(path);
  if (!stream) {
    throw CellGeometryError(path.string() + ": cannot open the cell geometry file");
  }
  std::ostringstream text;
  text << stream.rdbuf();
  return parse_cell_geometry(text.str(), path.string());
}

}  // namespace rigger::sim
