#include "control_config.hpp"

#include <cmath>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::control {
namespace {

constexpr double kDegToRad = kPi / 180.0;

// Turns a find_problem() result into the file's error.
template <typename T>
void check(const T& value, const Config& section) {
  if (auto p = find_problem(value)) throw ConfigError(section.file(), section.pointer() + p->pointer, p->problem);
}

std::string json_kind(const nlohmann::json& value) {
  if (value.is_object()) return "an object";
  if (value.is_array()) return "an array";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_number()) return "a number";
  return "null";
}

Eigen::Vector3d read_triple(const nlohmann::json& object, const char* key, const std::string& source,
                            const std::string& pointer) {
  const std::string where = pointer + "/" + key;
  const auto it = object.find(key);
  if (it == object.end()) throw ConfigError(source, where, "missing required key");
  if (it->is_array() && it->size() == 3) {
    Eigen::Vector3d out;
    bool ok = true;
    for (std::size_t i = 0; i < 3 && ok; ++i) {
      ok = (*it)[i].is_number() && std::isfinite((*it)[i].get<double>());
      if (ok) out[static_cast<Eigen::Index>(i)] = (*it)[i].get<double>();
    }
    if (ok) return out;
  }
  throw ConfigError(source, where, "expected an array of 3 finite numbers, got " + json_kind(*it));
}

}  // namespace

ControlConfig load_control_config(const Config& config) {
  ControlConfig out;
  read_into(config, control_settings(), out);
  // The rules each law keeps for itself (also for gains and limits changed at run time), then the loops'.
  const Config robot = config.child_or_empty("robot");
  const Config crane = config.child_or_empty("crane");
  check(out.robot, robot);
  check(out.crane, crane);
  check(out.visual_servo, config.child_or_empty("visual_servo"));
  // The laws refuse a step longer than max_time_step: a loop period above it would fault every cycle.
  if (1.0 / out.robot_rate_hz > out.robot.max_time_step.count())
    robot.fail("rate_hz", "the period 1/rate_hz must not exceed max_time_step_s");
  if (1.0 / out.crane_rate_hz > out.crane.max_time_step.count())
    crane.fail("rate_hz", "the period 1/rate_hz must not exceed max_time_step_s");
  config.finish();
  return out;
}

ControlConfig load_control_config_file(const std::string& path) {
  return load_control_config(Config::load(path));
}

Eigen::Isometry3d pose_from_config_json(const nlohmann::json& value, const std::string& source,
                                        const std::string& pointer) {
  if (!value.is_object())
    throw ConfigError(source, pointer,
                      "expected an object {\"position_m\": [..], \"rpy_deg\": [..]}, got " + json_kind(value));
  for (const auto& item : value.items())
    if (item.key() != "position_m" && item.key() != "rpy_deg" && item.key() != "comment")
      throw ConfigError(source, pointer + "/" + item.key(), "unknown key (expected position_m and rpy_deg)");
  const Eigen::Vector3d position_m = read_triple(value, "position_m", source, pointer);
  const Eigen::Vector3d rpy_rad = read_triple(value, "rpy_deg", source, pointer) * kDegToRad;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = position_m;
  return pose;
}

Eigen::Isometry3d insertion_offset_from_features(const nlohmann::json& features, const std::string& source) {
  if (!features.is_object()) throw ConfigError(source, "", "expected the features object, got " + json_kind(features));
  const auto insertion = features.find("insertion");
  if (insertion == features.end() || !insertion->is_object())
    throw ConfigError(source, "/insertion", "expected an object with pose_in_target (the object has no insertion)");
  const auto pose = insertion->find("pose_in_target");
  if (pose == insertion->end()) throw ConfigError(source, "/insertion/pose_in_target", "missing required key");
  return pose_from_config_json(*pose, source, "/insertion/pose_in_target");
}

Eigen::Isometry3d entity_pose_from_cell_file(const std::string& path, const std::string& entity_id) {
  cell::CellFile cell;
  try {
    cell = cell::load_cell_file(path);  // the one cell-file reader: bounded, every rule checked
  } catch (const cell::CellFileError& e) {
    throw ConfigError(path, e.pointer(), e.what());
  }
  return entity_pose_in_cell(cell, path, entity_id);
}

Eigen::Isometry3d entity_pose_in_cell(const cell::CellFile& cell, const std::string& source,
                                      const std::string& entity_id) {
  const cell::CellEntity* entity = cell.find(entity_id);
  if (entity == nullptr) throw ConfigError(source, "/entities", "no entity with id '" + entity_id + "'");
  if (entity->parent != "world")
    throw ConfigError(source, entity->pointer + "/parent",
                      "entity '" + entity_id + "' must have parent 'world', got '" + entity->parent + "'");
  if (!entity->pose_parent_entity) throw ConfigError(source, entity->pointer + "/pose", "missing required key");
  return *entity->pose_parent_entity;
}

Eigen::Isometry3d rope_attachment_in_cell(const cell::CellFile& cell, const std::string& source,
                                          const std::string& object) {
  const cell::CellEntity* entity = cell.find(object);
  if (entity == nullptr)
    throw ConfigError(source, "/entities",
                      "no entity with id '" + object + "' (rope_object, for the measured rope offset)");
  if (!entity->features.rope_attachment)
    throw ConfigError(source, entity->pointer, "object '" + object + "' has no rope_attachment feature");
  return *entity->features.rope_attachment;
}

}  // namespace rigger::control
