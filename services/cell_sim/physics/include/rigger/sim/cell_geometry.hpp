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
#include <utility>
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
  /// A calibration board on the tool (the robot entity's calibration_board): a massless geom of the
  /// gripper that nothing collides with, for the camera to see.
  std::optional<cell::CalibrationBoard> calibration_board;
};

struct GripperGeometry {
  double holding_force_n = 0.0;
  double flange_to_face_m = 0.0;
};

/// The object the crane carries: the one object with features.rope_attachment.
struct LoadGeometry {
  std::string id;                                                     ///< its entity id
  Eigen::Isometry3d pose_world_load = Eigen::Isometry3d::Identity();  ///< its entity frame
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();                   ///< bounding-box edge lengths
  double mass_kg = 0.0;
  Eigen::Isometry3d pose_load_rope_attachment = Eigen::Isometry3d::Identity();
  std::vector<NamedPose> grasp_frames;        ///< tool frames in the load frame
  std::vector<NamedPose> approach_waypoints;  ///< tool frames in the load frame
  /// Where the load sits when inserted: the load frame in the target's frame.
  std::optional<Eigen::Isometry3d> pose_target_load_inserted;
};

/// The load's insertion target (features.insertion.target), or the entity "target" when the load has no
/// insertion.
struct TargetGeometry {
  std::string id;                                                       ///< its entity id
  Eigen::Isometry3d pose_world_target = Eigen::Isometry3d::Identity();  ///< its entity frame
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();                     ///< bounding-box edge lengths
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

/// One solid of an object's STEP model as the physics collides it: the vertices of its tessellation (MuJoCo
/// collides their convex hull), in the object's frame.
struct ObjectSolid {
  std::vector<Eigen::Vector3d> vertices_m;
  double volume_m3 = 0.0;  ///< the solid's own volume (B-rep), > 0
};

/// An object entity as the physics builds it: one body named by the entity id, static (fixed to the world)
/// or free, with a box geom (the cell file's box shorthand) or one convex mesh geom per STEP solid.
struct ObjectGeometry {
  std::string id;
  std::string pointer;  ///< the entity in the cell file, for messages
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
  bool is_static = false;  ///< model.static: fixed to the world
  double mass_kg = 0.0;    ///< model.mass_kg, or the STEP volume times model.density_kg_m3; 0 for a static object without either
  /// The box shorthand: full edge lengths, and its centre in the object frame (from the model's "frame", as
  /// cell::box_centre_in_object_frame reads it). Absent for an object whose geometry is its STEP solids.
  std::optional<Eigen::Vector3d> box_size_m;
  Eigen::Vector3d box_centre_m = Eigen::Vector3d::Zero();
  std::vector<ObjectSolid> solids;  ///< the STEP solids when there is no box
  /// Where the crane's rope hooks (features.rope_attachment), in the object frame.
  std::optional<Eigen::Isometry3d> pose_object_rope_attachment;

  /// Bounding box of the geometry in the object frame: {centre, full size}.
  [[nodiscard]] std::pair<Eigen::Vector3d, Eigen::Vector3d> bounds_m() const;
};

struct CellGeometry {
  std::string source;  ///< file it came from, for messages
  CraneGeometry crane;
  RobotGeometry robot;
  GripperGeometry gripper;
  LoadGeometry load;
  TargetGeometry target;
  /// Absent when the cell has no entity "part" with a "part_fixture".
  std::optional<PartGeometry> part;
  /// Every object entity, in file order: each becomes a body of the model. The load is the one with a
  /// rope attachment, the target the load's insertion target (or the entity "target").
  std::vector<ObjectGeometry> objects;

  /// The grasp frame with this id, or nullopt.
  [[nodiscard]] std::optional<Eigen::Isometry3d> grasp_frame(const std::string& id) const;
};

/// Reads and checks a cell JSON file.  Throws CellGeometryError (file, JSON pointer, expectation).
CellGeometry load_cell_geometry(const std::filesystem::path& path);

/// Parses cell JSON text; `source` names it in error messages. The CAD rules' STEP models (model.step)
/// are read relative to `model_dir` (empty: the folder of `source`).  Throws CellGeometryError.
CellGeometry parse_cell_geometry(const std::string& json_text, const std::string& source,
                                 const std::filesystem::path& model_dir = {});

/// The physics' part of a validated cell file: entities "crane", "robot" and "gripper" with the attributes
/// the physics needs, and every object (its geometry read from its STEP model, relative to `model_dir`;
/// empty: the folder of file.source). Exactly one object carries a rope attachment (the load); the target is
/// its insertion target or the entity "target". Throws cell::CellFileError (file, JSON pointer, expectation):
/// an object without a mass that must move, a STEP model that cannot be read or has no closed solid.
CellGeometry cell_geometry_from(const cell::CellFile& file, const std::filesystem::path& model_dir = {});

}  // namespace rigger::sim
