#pragma once
// The part of the cell geometry contract (deploy/cell/simulated_cell.json) that the physics needs:
// poses resolved to the world frame, sizes, masses, crane ranges and the load's features. Read with the
// shared cell-file reader (rigger_cell_config); the crane, robot and gripper numbers are entity
// attributes checked here.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::sim {

/// Bad or missing cell geometry. what() names the file, the JSON pointer and what was expected (the cell
/// file reader's cell::CellFileError text), or what does not fit the physics model.
class CellGeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A named pose of a feature, in its owner's frame.
using NamedPose = cell::NamedPose;

struct CraneGeometry {
  /// Crane frame in the world: its x is the bridge travel, y the trolley travel.
  Eigen::Isometry3d pose_world_crane = Eigen::Isometry3d::Identity();
  double rail_height_m = 0.0;  ///< sheave height above the crane frame (m)
  Eigen::Vector2d bridge_range_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d trolley_range_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d rope_length_range_m = Eigen::Vector2d::Zero();
  /// Per axis (bridge, trolley, hoist); the PLC enforces them, the physics only reports them.
  Eigen::Vector3d max_speed_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_accel_mps2 = Eigen::Vector3d::Zero();
  double rated_load_kg = 0.0;
};

struct RobotGeometry {
  Eigen::Isometry3d pose_world_base = Eigen::Isometry3d::Identity();
  std::string model;
  double tool_length_m = 0.0;
};

struct GripperGeometry {
  double holding_force_n = 0.0;
  double flange_to_face_m = 0.0;
};

struct LoadGeometry {
  Eigen::Isometry3d pose_world_load = Eigen::Isometry3d::Identity();  ///< box centre
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();                   ///< full edge lengths
  double mass_kg = 0.0;
  Eigen::Isometry3d pose_load_rope_attachment = Eigen::Isometry3d::Identity();
  std::vector<NamedPose> grasp_frames;        ///< tool frames in the load frame
  std::vector<NamedPose> approach_waypoints;  ///< tool frames in the load frame
  /// Where the load sits when inserted: the load frame in the target's frame.
  std::optional<Eigen::Isometry3d> pose_target_load_inserted;
};

struct TargetGeometry {
  Eigen::Isometry3d pose_world_target = Eigen::Isometry3d::Identity();  ///< top-face centre
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
};

/// The small part the robot picks and places on its own (entity "part", a free box within the robot's
/// payload) and the table it sits on (entity "part_fixture", static, frame at its top-face centre).
struct PartGeometry {
  Eigen::Isometry3d pose_world_part = Eigen::Isometry3d::Identity();  ///< box centre
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();                   ///< full edge lengths
  double mass_kg = 0.0;
  Eigen::Isometry3d pose_world_fixture = Eigen::Isometry3d::Identity();  ///< top-face centre
  Eigen::Vector3d fixture_size_m = Eigen::Vector3d::Zero();
};

struct CellGeometry {
  std::string source;  ///< file it came from, for messages
  CraneGeometry crane;
  RobotGeometry robot;
  GripperGeometry gripper;
  LoadGeometry load;
  TargetGeometry target;
  /// Absent when the cell has no entity "part" (then the model keeps its part out of the way).
  std::optional<PartGeometry> part;

  /// The grasp frame with this id, or nullopt.
  [[nodiscard]] std::optional<Eigen::Isometry3d> grasp_frame(const std::string& id) const;
};

/// Reads and checks a cell JSON file.  Throws CellGeometryError (file, JSON pointer, expectation).
CellGeometry load_cell_geometry(const std::filesystem::path& path);

/// Parses cell JSON text; `source` names it in error messages. The CAD rules' STEP models (model.step)
/// are read relative to `model_dir` (empty: the folder of `source`).  Throws CellGeometryError.
CellGeometry parse_cell_geometry(const std::string& json_text, const std::string& source,
                                 const std::filesystem::path& model_dir = {});

/// The physics' part of a validated cell file: entities "crane", "robot", "gripper", "load" and "target"
/// with the attributes, model and features the physics needs, and optionally "part" (a box with a mass)
/// with its "part_fixture" (a box).  Throws cell::CellFileError.
CellGeometry cell_geometry_from(const cell::CellFile& file);

}  // namespace rigger::sim
