#include "rigger/sim/camera_scene.hpp"

#include <nlohmann/json.hpp>

#include "rigger/cell_config/calibration_board.hpp"

#include <algorithm>
#include <cmath>

namespace rigger::sim {
namespace {

/// k1 k2 p1 p2 k3: the most the renderer's CameraInfo (plumb_bob) carries.
constexpr std::size_t kPlumbBobCoefficients = 5;

// Markers must lie on a box face: on its plane (within this distance) and facing out of it.
constexpr double kOnFaceTolerance_m = 1e-3;
constexpr double kNormalAlignment = 0.999;

/// Throws unless the marker lies flat on one of the box's faces and faces outwards.
void check_marker_on_face(const cell::CellFile& file, const BoxObject& object, const MarkerSpec& marker,
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
              file.fail(pointer, "marker " + std::to_string(marker.id) + " within its face of \"" + object.id + "\"",
                        "a marker extending beyond the face");
            }
          }
        }
      }
      return;
    }
  }
  file.fail(
      pointer,
      "marker " + std::to_string(marker.id) + " flat on a face of \"" + object.id + "\", its z axis out of the box",
      "a marker off every face");
}

BoxObject box_object(const cell::CellFile& file, const cell::CellEntity& entity) {
  BoxObject object;
  object.id = entity.id;
  object.size_m = entity.model->size_m;
  object.pose_object_box = Eigen::Isometry3d(Eigen::Translation3d(cell::box_centre_in_object_frame(file, entity)));
  object.pose_world_object = file.pose_root_entity(entity.id);
  if (entity.features.markers) {
    const std::vector<cell::Marker>& items = entity.features.markers->items;
    for (std::size_t i = 0; i < items.size(); ++i) {
      const MarkerSpec marker{items[i].id, items[i].size_m, items[i].pose_entity_marker};
      check_marker_on_face(file, object, marker, entity.pointer + "/features/markers/items/" + std::to_string(i));
      object.markers.push_back(marker);
    }
  }
  return object;
}

CameraModel camera_model(const cell::CellFile& file, const cell::CellEntity& entity) {
  if (!entity.camera) {
    file.fail(entity.pointer + "/camera", "the intrinsics of camera \"" + entity.id + "\"", "nothing (missing key)");
  }
  const cell::CameraIntrinsics& camera = *entity.camera;
  if (camera.distortion.size() > kPlumbBobCoefficients) {
    file.fail(entity.pointer + "/camera/distortion", "4 or 5 numbers (k1 k2 p1 p2 [k3], the renderer's plumb_bob)",
              std::to_string(camera.distortion.size()) + " numbers");
  }
  return camera;
}

}  // namespace

CameraScene camera_scene_from(const cell::CellFile& file, const std::string& camera_id) {
  CameraScene scene;
  scene.camera_id = camera_id;
  const cell::CellEntity& camera = file.require(camera_id, "the camera to render");
  scene.camera = camera_model(file, camera);
  scene.pose_world_camera = file.pose_root_entity(camera_id);
  scene.dictionary_name = "DICT_4X4_50";
  bool dictionary_set = false;
  for (const cell::CellEntity& entity : file.entities) {
    if (entity.kind != cell::EntityKind::kObject || !entity.model) continue;
    const bool box = entity.model->shape == "box";
    // An object given by its STEP model alone: only its markers are the scene's (the model draws the rest).
    if (!box && !entity.features.markers) continue;
    if (const auto& markers = entity.features.markers) {
      if (dictionary_set && markers->dictionary != scene.dictionary_name) {
        file.fail(entity.pointer + "/features/markers/dictionary",
                  "the dictionary of every other object (" + scene.dictionary_name + ")",
                  "\"" + markers->dictionary + "\"");
      }
      scene.dictionary_name = markers->dictionary;
      dictionary_set = true;
    }
    if (box) {
      scene.objects.push_back(box_object(file, entity));
      continue;
    }
    BoxObject mesh;
    mesh.id = entity.id;
    mesh.pose_world_object = file.pose_root_entity(entity.id);
    for (const cell::Marker& item : entity.features.markers->items)
      mesh.markers.push_back({item.id, item.size_m, item.pose_entity_marker});
    scene.mesh_objects.push_back(std::move(mesh));
  }
  for (const cell::CellEntity& entity : file.entities) {
    if (!entity.calibration_board) continue;
    const cell::CalibrationBoard& board = *entity.calibration_board;
    if (dictionary_set && board.markers.dictionary != scene.dictionary_name) {
      file.fail(entity.pointer + "/calibration_board/markers/dictionary",
                "the dictionary of the objects' markers (" + scene.dictionary_name + ")",
                "\"" + board.markers.dictionary + "\"");
    }
    scene.dictionary_name = board.markers.dictionary;
    dictionary_set = true;
    BoxObject object;
    object.id = cell::calibration_board_id(entity.id);
    object.size_m = board.size_m;
    object.pose_world_object = file.pose_root_entity(entity.id);
    for (const cell::Marker& item : board.markers.items)
      object.markers.push_back({item.id, item.size_m, item.pose_entity_marker});
    scene.boards.push_back(std::move(object));
  }
  scene.dictionary = cell::marker_dictionary(scene.dictionary_name)->opencv_id;  // the reader knows the name
  return scene;
}

CameraScene parse_camera_scene(const nlohmann::json& cell, const std::string& source, const std::string& camera_id) {
  return cell::rethrow_as<CameraSceneError>(
      [&] { return camera_scene_from(cell::cell_file_from_json(cell, source), camera_id); });
}

CameraScene load_camera_scene(const std::filesystem::path& cell_json, const std::string& camera_id) {
  return cell::rethrow_as<CameraSceneError>(
      [&] { return camera_scene_from(cell::load_cell_file(cell_json), camera_id); });
}

}  // namespace rigger::sim
