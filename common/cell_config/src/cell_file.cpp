#include "rigger/cell_config/cell_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "cell_checker.hpp"
#include "entity_parser.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::cell {
namespace {

/// How far two boxes (centre pose, half extents) reach into each other: the smallest overlap of their
/// projections over the 15 separating axes of two boxes; <= 0 when they are apart or only touch.
double box_penetration(const Eigen::Isometry3d& a, const Eigen::Vector3d& half_a, const Eigen::Isometry3d& b,
                       const Eigen::Vector3d& half_b) {
  const Eigen::Matrix3d ra = a.linear();
  const Eigen::Matrix3d rb = b.linear();
  const Eigen::Vector3d t = b.translation() - a.translation();
  double least = std::numeric_limits<double>::infinity();
  const auto test = [&](Eigen::Vector3d axis) {
    if (axis.norm() < 1e-9) return;  // parallel edges: the face axes cover it
    axis.normalize();
    double reach = 0.0;
    for (int i = 0; i < 3; ++i) {
      reach += half_a(i) * std::abs(ra.col(i).dot(axis)) + half_b(i) * std::abs(rb.col(i).dot(axis));
    }
    least = std::min(least, reach - std::abs(t.dot(axis)));
  };
  for (int i = 0; i < 3; ++i) {
    test(ra.col(i));
    test(rb.col(i));
    for (int j = 0; j < 3; ++j) test(ra.col(i).cross(rb.col(j)));
  }
  return least;
}

/// Static objects with a box may touch, not overlap (by more than 1 mm): the physics cannot push fixed
/// bodies apart, so an overlap would be a drawing error that shows only as objects jumping off them.
void check_static_boxes_apart(const CellFile& file) {
  constexpr double kTolerance_m = 0.001;
  std::vector<const CellEntity*> boxes;
  for (const CellEntity& e : file.entities) {
    if (e.model && e.model->is_static && e.model->shape == "box") boxes.push_back(&e);
  }
  for (std::size_t j = 1; j < boxes.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const CellEntity& a = *boxes[i];
      const CellEntity& b = *boxes[j];
      const Eigen::Isometry3d box_a =
          file.pose_root_entity(a.id) * Eigen::Translation3d(box_centre_in_object_frame(file, a));
      const Eigen::Isometry3d box_b =
          file.pose_root_entity(b.id) * Eigen::Translation3d(box_centre_in_object_frame(file, b));
      const double depth = box_penetration(box_a, 0.5 * a.model->size_m, box_b, 0.5 * b.model->size_m);
      if (depth > kTolerance_m) {
        file.fail(b.pointer + "/pose", "static objects apart (they may touch, not overlap)",
                  "its box overlaps static object \"" + a.id + "\" (" + a.pointer + ") by " +
                      std::to_string(static_cast<int>(std::round(depth * 1000.0))) + " mm");
      }
    }
  }
}

std::string format_error(const std::string& file, const std::string& pointer, const std::string& expected,
                         const std::string& got) {
  std::string text = file + ": " + (pointer.empty() ? std::string("(document)") : pointer) + ": expected " + expected;
  if (!got.empty()) text += ", got " + got;
  return text;
}

}  // namespace

CellFileError::CellFileError(std::string file, std::string pointer, std::string expected, std::string got)
    : std::runtime_error(format_error(file, pointer, expected, got)),
      file_(std::move(file)),
      pointer_(std::move(pointer)),
      expected_(std::move(expected)) {}

const CellEntity* CellFile::find(std::string_view id) const {
  const auto it = std::find_if(entities.begin(), entities.end(), [&](const CellEntity& e) { return e.id == id; });
  return it == entities.end() ? nullptr : &*it;
}

const CellEntity& CellFile::require(std::string_view id, std::string_view purpose) const {
  const CellEntity* entity = find(id);
  if (entity == nullptr) {
    fail("/entities", "an entity with id \"" + std::string(id) + "\" (" + std::string(purpose) + ")", "none");
  }
  return *entity;
}

Eigen::Isometry3d CellFile::pose_root_entity(std::string_view id) const {
  // A validated file has known parents and no cycles, so the walk ends at a root frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (const CellEntity* entity = &require(id, "a pose lookup"); entity != nullptr;
       entity = entity->parent.empty() ? nullptr : find(entity->parent)) {
    if (entity->pose_parent_entity) pose = *entity->pose_parent_entity * pose;
  }
  return pose;
}

void CellFile::fail(const std::string& pointer, const std::string& expected, const std::string& got) const {
  throw CellFileError(source, pointer, expected, got);
}

void CellFile::require_cad_derived(std::string_view reader) const {
  for (const CellEntity& entity : entities) {
    if (const CadRule* rule = entity.features.pending_cad()) {
      fail(rule->pointer,
           "features derived from the STEP models before " + std::string(reader) +
               " uses them (cell::load_cell_file_with_cad)",
           "a CAD rule of \"" + entity.id + "\" not derived");
    }
  }
}

AttributeReader::AttributeReader(const CellFile& file, const CellEntity& entity) : file_(file), entity_(entity) {}

std::string AttributeReader::pointer(std::string_view key) const {
  return join_pointer(entity_.pointer + "/attributes", key);
}

const json& AttributeReader::value(std::string_view key, const std::string& expected) const {
  const auto it = entity_.attributes.find(key);
  if (it == entity_.attributes.end()) file_.fail(pointer(key), expected, "nothing (missing key)");
  return *it;
}

double AttributeReader::number(std::string_view key) const {
  return Checker(file_.source).number(value(key, "a number"), pointer(key));
}

double AttributeReader::positive(std::string_view key) const {
  return Checker(file_.source).positive(value(key, "a number > 0"), pointer(key));
}

Eigen::Vector2d AttributeReader::range(std::string_view key) const {
  const std::string expected = "[min, max], two numbers with min < max";
  const json& range_value = value(key, expected);
  const auto values = Checker(file_.source).numbers(range_value, pointer(key), {2}, expected);
  if (!(values[0] < values[1])) file_.fail(pointer(key), expected, describe_json(range_value));
  return {values[0], values[1]};
}

Eigen::Vector3d AttributeReader::positive3(std::string_view key) const {
  const std::string expected = "an array of 3 numbers > 0";
  const json& triple = value(key, expected);
  const auto values = Checker(file_.source).numbers(triple, pointer(key), {3}, expected);
  if (*std::min_element(values.begin(), values.end()) <= 0.0) file_.fail(pointer(key), expected, describe_json(triple));
  return {values[0], values[1], values[2]};
}

std::string AttributeReader::text(std::string_view key) const {
  return Checker(file_.source).string(value(key, "a string"), pointer(key));
}

Eigen::Vector3d box_centre_in_object_frame(const CellFile& file, const CellEntity& entity) {
  if (!entity.model || entity.model->shape != "box") {
    file.fail(entity.pointer + "/model/shape", "\"box\" (an object with a box)", "no box");
  }
  const ObjectModel& model = *entity.model;
  const std::string& frame = model.frame;
  if (frame.empty() || frame == "box centre" || frame == "box center") return Eigen::Vector3d::Zero();
  if (frame == "centre of the top face" || frame == "center of the top face") {
    return Eigen::Vector3d(0, 0, -0.5 * model.size_m.z());
  }
  if (frame == "centre of the bottom face" || frame == "center of the bottom face") {
    return Eigen::Vector3d(0, 0, 0.5 * model.size_m.z());
  }
  file.fail(entity.pointer + "/model/frame",
            "\"box centre\", \"centre of the top face\" or \"centre of the bottom face\"", "\"" + frame + "\"");
}

std::filesystem::path cell_model_folder(const std::filesystem::path& cell_file) {
  return cell_file.parent_path().empty() ? std::filesystem::path(".") : cell_file.parent_path();
}

CellFile load_cell_file(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::ifstream file(path, std::ios::binary);
  if (!file) throw CellFileError(source, "", "a readable file", std::strerror(errno));
  std::string text;
  char buffer[65536];
  while (file.read(buffer, sizeof buffer) || file.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(file.gcount()));
    if (text.size() > kMaxCellFileBytes) {
      throw CellFileError(source, "", "at most " + std::to_string(kMaxCellFileBytes) + " bytes", "a larger file");
    }
  }
  if (file.bad()) throw CellFileError(source, "", "a readable file", "a read error");
  return parse_cell_file(text, source);
}

CellFile parse_cell_file(std::string_view text, const std::string& source) {
  if (text.size() > kMaxCellFileBytes) {
    throw CellFileError(source, "", "at most " + std::to_string(kMaxCellFileBytes) + " bytes",
                        std::to_string(text.size()) + " bytes");
  }
  // The one bounded parser (rigger/base/bounded_json.hpp) refuses deep nesting and duplicate keys
  // (which nlohmann::json would silently resolve to the last one) while it parses.
  const JsonParseResult parsed = parse_json_bounded(text, JsonLimits{kMaxCellFileBytes, static_cast<std::size_t>(kMaxCellFileDepth)});
  if (!parsed.ok()) {
    const JsonParseError& error = *parsed.error;
    throw CellFileError(source, error.pointer, "valid JSON",
                        "line " + std::to_string(error.line) + ", column " + std::to_string(error.column) + ": " +
                            error.message);
  }
  return cell_file_from_json(parsed.value, source);
}

CellFile cell_file_from_json(const json& document, const std::string& source) {
  const Checker check(source);
  check.object(document, "", {"cell_version", "description", "entities"});
  CellFile file;
  file.source = source;
  file.cell_version =
      static_cast<int>(check.integer(check.require(document, "", "cell_version", "the format version 1"),
                                     "/cell_version", kCellVersion, kCellVersion));
  if (const json* description = Checker::find(document, "description")) {
    file.description = check.string(*description, "/description");
  }
  const json& entities = check.require(document, "", "entities", "an array of entities");
  if (!entities.is_array() || entities.empty())
    check.fail("/entities", "a non-empty array of entities", describe_json(entities));

  EntityParser parser(check);
  std::map<std::string, std::size_t> index_of;
  for (std::size_t i = 0; i < entities.size(); ++i) {
    const std::string pointer = "/entities/" + std::to_string(i);
    CellEntity entity = parser.parse(entities[i], pointer);
    const auto [it, inserted] = index_of.emplace(entity.id, i);
    if (!inserted) {
      check.fail(pointer + "/id", "an entity id unique in the cell",
                 "\"" + entity.id + "\", already used at /entities/" + std::to_string(it->second));
    }
    file.entities.push_back(std::move(entity));
  }
  // References are resolved after every id is known, so the file may list entities in any order.
  std::map<std::pair<std::string, int>, std::string> marker_owner;  // (dictionary, id) -> pointer
  std::string hooked;  // the entity whose rope attachment the crane's rope hooks
  for (std::size_t i = 0; i < file.entities.size(); ++i) {
    const CellEntity& entity = file.entities[i];
    const std::string pointer = "/entities/" + std::to_string(i);
    if (!entity.parent.empty() && index_of.count(entity.parent) == 0) {
      check.fail(pointer + "/parent", "the id of an entity of this cell", "unknown entity \"" + entity.parent + "\"");
    }
    if (entity.features.insertion) {
      const std::string& target = entity.features.insertion->target;
      if (index_of.count(target) == 0 || target == entity.id) {
        check.fail(pointer + "/features/insertion/target", "the id of another entity of this cell",
                   "\"" + target + "\"");
      }
      const CellEntity& target_entity = file.entities[index_of.at(target)];
      if (entity.features.insertion->cad && (!target_entity.model || target_entity.model->step.empty())) {
        check.fail(pointer + "/features/insertion/cad/target_face",
                   "an insertion target whose model names a STEP file (model.step)",
                   "\"" + target + "\" without one");
      }
    }
    // The crane carries one load: a rope attachment declared on a second object is a mistake a simulator
    // would only find when it builds the cell (moving the rope is one revision that changes both).
    if (entity.features.rope_attachment) {
      if (!hooked.empty()) {
        check.fail(pointer + "/features/rope_attachment", "one object with a rope attachment (the crane carries one load)",
                   "a second one: \"" + hooked + "\" has one");
      }
      hooked = entity.id;
    }
    // Objects' markers and calibration boards' markers share one id space per dictionary: the tracker
    // must know which entity a detected marker belongs to.
    const auto claim_markers = [&](const MarkerLayout& layout, const std::string& layout_pointer) {
      for (std::size_t m = 0; m < layout.items.size(); ++m) {
        const std::string marker_pointer = layout_pointer + "/items/" + std::to_string(m) + "/id";
        const auto [it, inserted] =
            marker_owner.emplace(std::make_pair(layout.dictionary, layout.items[m].id), marker_pointer);
        if (!inserted) {
          check.fail(marker_pointer, "a marker id unique in the cell for dictionary " + layout.dictionary,
                     std::to_string(layout.items[m].id) + ", already used at " + it->second);
        }
      }
    };
    if (entity.features.markers) claim_markers(*entity.features.markers, pointer + "/features/markers");
    if (entity.calibration_board)
      claim_markers(entity.calibration_board->markers, pointer + "/calibration_board/markers");
  }
  for (std::size_t i = 0; i < file.entities.size(); ++i) {
    std::vector<std::string> chain{file.entities[i].id};
    std::string parent = file.entities[i].parent;
    while (!parent.empty()) {
      chain.push_back(parent);
      if (parent == file.entities[i].id) {
        std::string cycle;
        for (const auto& id : chain) cycle += (cycle.empty() ? "" : " -> ") + id;
        check.fail("/entities/" + std::to_string(i) + "/parent", "a frame tree without cycles", "the cycle " + cycle);
      }
      // A cycle not through entity i is reported when the loop reaches one of its members.
      if (chain.size() > file.entities.size() + 1) break;
      parent = file.entities[index_of.at(parent)].parent;
    }
  }
  check_static_boxes_apart(file);
  return file;
}

}  // namespace rigger::cell
