#pragma once
/// @file
/// What the simulated camera needs from the cell configuration (deploy/cell/simulated_cell.json):
/// the camera's intrinsics and pose, and each boxed object with its fiducial markers. Read with the
/// shared cell-file reader (rigger_cell_config); the rules only the renderer needs (one dictionary,
/// markers flat on a box face, named box frames, plumb_bob distortion) are checked here.

#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>

#include "rigger/cell_config/cell_file.hpp"

#include <array>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace rigger::sim {

/// A malformed or unusable cell configuration. what() names the file, the JSON pointer and what was
/// expected there.
class CameraSceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The simulated camera is the cell file's: its intrinsics, rate and pixel noise (noise_stddev, grey
/// levels 0..255). The renderer supports only zero distortion.
using CameraModel = cell::CameraIntrinsics;

/// A square fiducial marker printed on an object. Marker frame (OpenCV ArUco convention): origin at
/// the marker centre, x to the right of the printed image, y up, z out of the printed face. The
/// marker's black outer border is size_m wide; the white quiet zone around it is not included.
struct MarkerSpec {
  int id = 0;
  double size_m = 0.0;
  Eigen::Isometry3d pose_object_marker = Eigen::Isometry3d::Identity();
};

/// A rigid box-shaped object with markers on its faces.
struct BoxObject {
  std::string id;
  /// Full edge lengths along the box axes, metres.
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  /// The box centre (axes along the edges) in the object's frame: the object frame need not be
  /// the box centre (the target's is the centre of its top face).
  Eigen::Isometry3d pose_object_box = Eigen::Isometry3d::Identity();
  std::vector<MarkerSpec> markers;
  /// The object's pose in the world as configured (the scenario's initial pose).
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
};

/// Everything the camera renders, read from one cell configuration.
struct CameraScene {
  std::string camera_id;
  CameraModel camera;
  Eigen::Isometry3d pose_world_camera = Eigen::Isometry3d::Identity();
  /// OpenCV predefined dictionary id (cv::aruco::PREDEFINED_DICTIONARY_NAME) shared by all markers.
  int dictionary = 0;
  std::string dictionary_name;
  std::vector<BoxObject> objects;
  /// The objects given by their STEP model alone that carry markers: size_m zero, their markers not
  /// checked against a box. The MuJoCo camera draws such a marker only where a geom of the model lies
  /// under it (within 5 mm); the rasteriser, which draws boxes, does not draw them.
  std::vector<BoxObject> mesh_objects;
  /// The calibration boards robots carry on their tools (cell file key calibration_board), each by
  /// cell::calibration_board_id(robot): a box centred on its frame, its markers on its +z face. Their
  /// pose_world_object is the robot's base (where the board is before the physics poses the tool). Both
  /// renderers draw them; the MuJoCo model holds the board's geom on the tool (CellPhysics).
  std::vector<BoxObject> boards;
};

/// Reads the camera scene from a cell configuration file.
/// camera_id names the entity holding the "camera" block; objects are the entities of kind
/// "object" whose model is a box. Throws CameraSceneError naming the file and JSON pointer.
CameraScene load_camera_scene(const std::filesystem::path& cell_json, const std::string& camera_id = "camera");

/// Same, from parsed JSON; source names the origin in error messages.
CameraScene parse_camera_scene(const nlohmann::json& cell, const std::string& source,
                               const std::string& camera_id = "camera");

/// Same, from a validated cell file. Throws cell::CellFileError naming the file and JSON pointer.
CameraScene camera_scene_from(const cell::CellFile& file, const std::string& camera_id = "camera");

}  // namespace rigger::sim
