#include "rigger/sim/camera_scene.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/aruco/dictionary.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <utility>

namespace rigger::sim {
namespace {

using nlohmann::json;

constexpr double kDegToRad = M_PI / 180.0;
// Markers must lie on a box face: on its plane (within this distance) and facing out of it.
constexpr double kOnFaceTolerance_m = 1e-3;
constexpr double kNormalAlignment = 0.999;

/// Carries the source name and builds "source: /json/pointer: message" errors.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& what) const {
    throw CameraSceneError(source_ + ": " + (pointer.empty() ? std::string("/") : pointer) + ": " + what);
  }

  const json& member(const json& object, const std::string& pointer, const std::string& key) const {
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
    const double v = value.get<double>();
    if (!std::isfinite(v)) {
      fail(pointer, "expected a finite number");
    }
    return v;
  }

  double positive(const json& value, const std::string& pointer) const {
    const double v = number(value, pointer);
    if (v <= 0.0) {
      fail(pointer, "expected a positive number, got " + value.dump());
    }
    return v;
  }

  int positive_int(const json& value, const std::string& pointer) const {
    if (!value.is_number_integer() || value.get<long long>() <= 0 || value.get<long long>() > 100000) {
      fail(pointer, "expected a positive integer (at most 100000), got " + value.dump());
    }
    return value.get<int>();
  }

  std::string string(const json& value, const std::string& pointer) const {
    if (!value.is_string()) {
      fail(pointer, "expected a string");
    }
    return value.get<std::string>();
  }

  Eigen::Vector3d vector3(const json& value, const std::string& pointer) const {
    if (!value.is_array() || value.size() != 3) {
      fail(pointer, "expected an array of 3 numbers");
    }
    return {number(value[0], pointer + "/0"), number(value[1], pointer + "/1"), number(value[2], pointer + "/2")};
  }

  Eigen::Isometry3d pose(const json& value, const std::string& pointer) const {
    return pose_from_rpy_deg(vector3(member(value, pointer, "position_m"), pointer + "/position_m"),
                             vector3(member(value, pointer, "rpy_deg"), pointer + "/rpy_deg"));
  }

 private:
  std::string source_;
};

struct EntityRef {
  const json* entity;
  std::string pointer;
};

/// The entity's pose in the world: its pose composed with its parents' (an entity without a pose
/// sits at its parent's origin).
Eigen::Isometry3d world_pose(const Reader& reader, const std::map<std::string, EntityRef>& entities,
                             const std::string& id) {
  Eigen::Isometry3d pose_world = Eigen::Isometry3d::Identity();
  std::set<std::string> seen;
  std::string current = id;
  while (current != "world") {
    if (!seen.insert(current).second) {
      reader.fail(entities.at(id).pointer, "parent chain of '" + id + "' has a cycle");
    }
    const auto it = entities.find(current);
    if (it == entities.end()) {
      reader.fail(entities.at(id).pointer, "parent '" + current + "' of '" + id + "' is not an entity");
    }
    const json& entity = *it->second.entity;
    const std::string& pointer = it->second.pointer;
    if (entity.contains("pose")) {
      pose_world = reader.pose(entity["pose"], pointer + "/pose") * pose_world;
    }
    if (!entity.contains("parent")) {
      if (entity.value("kind", "") == "frame") {
        break;
      }
      reader.fail(pointer + "/parent", "missing (required for '" + current + "')");
    }
    current = reader.string(entity["parent"], pointer + "/parent");
  }
  return pose_world;
}

Eigen::Isometry3d box_in_object_frame(const Reader& reader, const std::string& frame, const Eigen::Vector3d& size_m,
                                      const std::string& pointer) {
  Eigen::Isometry3d pose_object_box = Eigen::Isometry3d::Identity();
  if (frame == "box centre" || frame == "box center") {
    return pose_object_box;
  }
  if (frame == "centre of the top face" || frame == "center of the top face") {
    pose_object_box.translation() = Eigen::Vector3d(0, 0, -0.5 * size_m.z());
    return pose_object_box;
  }
  if (frame == "centre of the bottom face" || frame == "center of the bottom face") {
    pose_object_box.translation() = Eigen::Vector3d(0, 0, 0.5 * size_m.z());
    return pose_object_box;
  }
  reader.fail(pointer,
              "expected \"box centre\", \"centre of the top face\" or \"centre of the "
              "bottom face\", got \"" +
                  frame + "\"");
}

/// Throws unless the marker lies flat on one of the box's faces and faces outwards.
void check_marker_on_face(const Reader& reader, const BoxObject& object, const MarkerSpec& marker,
                          const std::string& pointer) {
  const Eigen::Isometry3d pose_box_marker = object.pose_object_box.inverse() * marker.pose_object_marker;
  const Eigen::Vector3d normal = pose_box_marker.linear().col(2);
  const Eigen::Vector3d half = 0.5 * object.size_m;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {-1.0, 1.0}) {
      const Eigen::Vector3d face_normal = sign * Eigen::Vector3d::Unit(axis);
      if (normal.dot(face_normal) < kNormalAlignment) {
        continue;
      }
      const Eigen::Vector3d& centre = pose_box_marker.translation();
      if (std::abs(centre[axis] - sign * half[axis]) > kOnFaceTolerance_m) {
        continue;
      }
      // All four corners of the printed marker must be on the face.
      const double reach = 0.5 * marker.size_m;
      for (const double u : {-reach, reach}) {
        for (const double v : {-reach, reach}) {
          const Eigen::Vector3d corner = pose_box_marker * Eigen::Vector3d(u, v, 0);
          for (int k = 0; k < 3; ++k) {
            if (k != axis && std::abs(corner[k]) > half[k] + kOnFaceTolerance_m) {
              reader.fail(pointer,
                          "marker " + std::to_string(marker.id) + " extends beyond its face of '" + object.id + "'");
            }
          }
        }
      }
      return;
    }
  }
  reader.fail(pointer, "marker " + std::to_string(marker.id) + " does not lie on a face of '" + object.id +
                           "' with its z axis pointing out of the box");
}

BoxObject parse_object(const Reader& reader, const json& entity, const std::string& pointer, const std::string& id,
                       int& dictionary, std::string& dictionary_name) {
  BoxObject object;
  object.id = id;
  const json& model = reader.member(entity, pointer, "model");
  const std::string model_pointer = pointer + "/model";
  const std::string shape = reader.string(reader.member(model, model_pointer, "shape"), model_pointer + "/shape");
  if (shape != "box") {
    reader.fail(model_pointer + "/shape", "expected \"box\" (the only shape the camera renders)");
  }
  object.size_m = reader.vector3(reader.member(model, model_pointer, "size_m"), model_pointer + "/size_m");
  for (int k = 0; k < 3; ++k) {
    if (object.size_m[k] <= 0.0) {
      reader.fail(model_pointer + "/size_m/" + std::to_string(k), "expected a positive length");
    }
  }
  const std::string frame =
      model.contains("frame") ? reader.string(model["frame"], model_pointer + "/frame") : std::string("box centre");
  object.pose_object_box = box_in_object_frame(reader, frame, object.size_m, model_pointer + "/frame");

  if (!entity.contains("features") || !entity["features"].contains("markers")) {
    return object;
  }
  const std::string markers_pointer = pointer + "/features/markers";
  const json& markers = entity["features"]["markers"];
  const std::string name =
      reader.string(reader.member(markers, markers_pointer, "dictionary"), markers_pointer + "/dictionary");
  int dict = 0;
  try {
    dict = aruco_dictionary_from_name(name);
  } catch (const std::invalid_argument& e) {
    reader.fail(markers_pointer + "/dictionary", e.what());
  }
  if (!dictionary_name.empty() && dictionary_name != name) {
    reader.fail(markers_pointer + "/dictionary",
                "all objects must use one dictionary (" + dictionary_name + "), got " + name);
  }
  dictionary = dict;
  dictionary_name = name;
  const int dictionary_size = cv::aruco::getPredefinedDictionary(dict)->bytesList.rows;

  const json& items = reader.member(markers, markers_pointer, "items");
  if (!items.is_array()) {
    reader.fail(markers_pointer + "/items", "expected an array");
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string item_pointer = markers_pointer + "/items/" + std::to_string(i);
    const json& item = items[i];
    MarkerSpec marker;
    const json& id_value = reader.member(item, item_pointer, "id");
    if (!id_value.is_number_integer() || id_value.get<long long>() < 0 ||
        id_value.get<long long>() >= dictionary_size) {
      reader.fail(item_pointer + "/id", "expected an integer in [0, " + std::to_string(dictionary_size) + ") for " +
                                            name + ", got " + id_value.dump());
    }
    marker.id = id_value.get<int>();
    marker.size_m = reader.positive(reader.member(item, item_pointer, "size_m"), item_pointer + "/size_m");
    marker.pose_object_marker = reader.pose(reader.member(item, item_pointer, "pose"), item_pointer + "/pose");
    check_marker_on_face(reader, object, marker, item_pointer);
    object.markers.push_back(marker);
  }
  return object;
}

CameraModel parse_camera(const Reader& reader, const json& block, const std::string& pointer) {
  CameraModel camera;
  camera.width_px = reader.positive_int(reader.member(block, pointer, "width"), pointer + "/width");
  camera.height_px = reader.positive_int(reader.member(block, pointer, "height"), pointer + "/height");
  camera.fx_px = reader.positive(reader.member(block, pointer, "fx"), pointer + "/fx");
  camera.fy_px = reader.positive(reader.member(block, pointer, "fy"), pointer + "/fy");
  camera.cx_px = reader.number(reader.member(block, pointer, "cx"), pointer + "/cx");
  camera.cy_px = reader.number(reader.member(block, pointer, "cy"), pointer + "/cy");
  if (block.contains("distortion")) {
    const json& d = block["distortion"];
    if (!d.is_array() || d.size() != 5) {
      reader.fail(pointer + "/distortion", "expected 5 numbers (k1 k2 p1 p2 k3)");
    }
    for (std::size_t k = 0; k < 5; ++k) {
      camera.distortion[k] = reader.number(d[k], pointer + "/distortion/" + std::to_string(k));
    }
  }
  if (block.contains("rate_hz")) {
    camera.rate_hz = reader.positive(block["rate_hz"], pointer + "/rate_hz");
  }
  if (block.contains("noise_stddev")) {
    camera.noise_stddev = reader.number(block["noise_stddev"], pointer + "/noise_stddev");
    if (camera.noise_stddev < 0.0) {
      reader.fail(pointer + "/noise_stddev", "expected a number >= 0 (grey levels)");
    }
  }
  return camera;
}

}  // namespace

Eigen::Isometry3d pose_from_rpy_deg(const Eigen::Vector3d& position_m, const Eigen::Vector3d& rpy_deg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_deg.z() * kDegToRad, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_deg.y() * kDegToRad, Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_deg.x() * kDegToRad, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = position_m;
  return pose;
}

int aruco_dictionary_from_name(const std::string& name) {
  static const std::map<std::string, int> kDictionaries = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
  };
  const auto it = kDictionaries.find(name);
  if (it == kDictionaries.end()) {
    throw std::invalid_argument("unknown ArUco dictionary \"" + name +
                                "\" (expected e.g. DICT_4X4_50, DICT_5X5_100, DICT_6X6_250)");
  }
  return it->second;
}

CameraScene parse_camera_scene(const nlohmann::json& cell, const std::string& source, const std::string& camera_id) {
  const Reader reader(source);
  const json& entities = reader.member(cell, "", "entities");
  if (!entities.is_array()) {
    reader.fail("/entities", "expected an array");
  }
  std::map<std::string, EntityRef> by_id;
  for (std::size_t i = 0; i < entities.size(); ++i) {
    const std::string pointer = "/entities/" + std::to_string(i);
    const std::string id = reader.string(reader.member(entities[i], pointer, "id"), pointer + "/id");
    if (!by_id.emplace(id, EntityRef{&entities[i], pointer}).second) {
      reader.fail(pointer + "/id", "duplicate entity id '" + id + "'");
    }
  }

  CameraScene scene;
  scene.camera_id = camera_id;
  const auto camera_it = by_id.find(camera_id);
  if (camera_it == by_id.end()) {
    reader.fail("/entities", "no entity with id '" + camera_id + "'");
  }
  const std::string camera_pointer = camera_it->second.pointer;
  scene.camera = parse_camera(reader, reader.member(*camera_it->second.entity, camera_pointer, "camera"),
                              camera_pointer + "/camera");
  scene.pose_world_camera = world_pose(reader, by_id, camera_id);

  scene.dictionary = cv::aruco::DICT_4X4_50;
  std::map<int, std::string> marker_owner;
  for (std::size_t i = 0; i < entities.size(); ++i) {
    const json& entity = entities[i];
    if (entity.value("kind", "") != "object" || !entity.contains("model")) {
      continue;
    }
    const std::string pointer = "/entities/" + std::to_string(i);
    const std::string id = entity["id"].get<std::string>();
    BoxObject object = parse_object(reader, entity, pointer, id, scene.dictionary, scene.dictionary_name);
    object.pose_world_object = world_pose(reader, by_id, id);
    for (const MarkerSpec& marker : object.markers) {
      const auto [it, inserted] = marker_owner.emplace(marker.id, id);
      if (!inserted) {
        reader.fail(pointer + "/features/markers",
                    "marker id " + std::to_string(marker.id) + " is used twice (also on '" + it->second + "')");
      }
    }
    scene.objects.push_back(std::move(object));
  }
  if (scene.dictionary_name.empty()) {
    scene.dictionary_name = "DICT_4X4_50";
  }
  return scene;
}

CameraScene load_camera_scene(const std::filesystem::path& cell_json, const std::string& camera_id) {
  std::ifstream in(cell_json);
  if (!in) {
    throw CameraSceneError(cell_json.string() + ": cannot open the cell configuration");
  }
  json cell;
  try {
    cell = json::parse(in);
  } catch (const json::parse_error& e) {
    throw CameraSceneError(cell_json.string() + ": not valid JSON: " + e.what());
  }
  return parse_camera_scene(cell, cell_json.string(), camera_id);
}

}  // namespace rigger::sim
