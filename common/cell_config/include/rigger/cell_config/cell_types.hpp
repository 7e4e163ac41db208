#pragma once
/// @file
/// The typed contents of a cell file (deploy/cell/*.json, format in docs/world-model.md): entity kinds,
/// CAD features, object models, camera intrinsics, and the file's pose convention. Pure C++ (Eigen);
/// value types, no shared state.
///
/// Poses are `Eigen::Isometry3d` named `pose_<frame>_<entity>`: the pose of `entity` expressed in `frame`
/// (it maps points from the entity's frame into `frame`). Metres and radians.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

namespace rigger::cell {

/// What an entity is. Only frames may be roots of the frame tree.
enum class EntityKind { kObject, kDevice, kFrame };

/// "object", "device" or "frame" (the spelling used in the cell file and on the wire).
std::string_view to_string(EntityKind kind);
/// Parses "object", "device" or "frame"; std::nullopt for anything else.
std::optional<EntityKind> entity_kind_from_string(std::string_view text);

/// A face, edge or vertex of an object's STEP model, named as docs/cad.md's references are: its kind,
/// its index (OCCT's TopExp::MapShapes order) and its geometric signature, which must still match the
/// model (an edited model is detected, not silently used). No sha256: regenerating a STEP file changes
/// its bytes (the header's timestamp) but not its geometry.
struct CadReference {
  std::string kind;  ///< "face", "edge" or "vertex"
  int index = -1;
  std::string type;  ///< signature type: "plane", "cylinder", "line", ...
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  std::string pointer;  ///< where it is in the cell file (errors name it)
};

/// How a feature's pose follows from an object's STEP model (docs/world-model.md, "CAD rules").
enum class CadRuleKind {
  kFace,       ///< origin at a face's centroid, z along its normal (out or into), x along an edge
  kHole,       ///< origin at a hole's entry, z along its axis out of the hole
  kMateFaces,  ///< insertion: this object's face against the target's face, normals opposite
};

/// "face", "hole", "mate_faces"; std::nullopt for anything else.
std::optional<CadRuleKind> cad_rule_from_string(std::string_view text);

/// A pin of a `mate_faces` insertion: a hole of this object on the axis of a hole of the target.
struct CadPin {
  CadReference hole;         ///< one cylindrical face of this object's hole
  CadReference target_hole;  ///< one cylindrical face of the target's hole
};

/// A feature defined by a rule over the STEP model instead of by numbers. The pose it stands for is
/// filled in by cell::derive_cad_features (rigger_cell_cad), which sets `derived`.
struct CadRule {
  CadRuleKind rule = CadRuleKind::kFace;
  /// kFace: the face; kHole: one cylindrical face of the hole; kMateFaces: this object's face.
  CadReference face;
  bool z_into = false;                 ///< kFace: z against the outward normal (a tool approaching)
  std::optional<CadReference> x_edge;  ///< kFace: x along this straight edge (else the model's x projected)
  bool x_reversed = false;             ///< kFace: x against the edge's direction
  double standoff_m = 0.0;             ///< kFace: origin moved this far out along the outward normal
  std::optional<CadReference> target_face;  ///< kMateFaces: the face of the insertion target's model
  /// kMateFaces: up to two pins. One puts its holes on one axis (the faces' frames keep the turn about
  /// it); two also turn the object so that the second pair lines up.
  std::vector<CadPin> pins;
  std::string pointer;                      ///< the "cad" object's JSON pointer
  bool derived = false;                     ///< the pose has been derived from the model
};

/// A named pose feature of an entity (grasp frame, approach waypoint), in the entity's own frame.
struct NamedPose {
  std::string id;
  Eigen::Isometry3d pose_entity_feature = Eigen::Isometry3d::Identity();
  std::optional<CadRule> cad;  ///< set when the pose comes from the STEP model
};

/// A screw hole: where (in the entity's frame, z along the screw axis), which screw and how tight.
struct ScrewHole {
  std::string id;
  Eigen::Isometry3d pose_entity_hole = Eigen::Isometry3d::Identity();
  std::string screw_type;  ///< e.g. "M12x40"
  double torque_nm = 0.0;  ///< tightening torque, N m, > 0
  std::optional<CadRule> cad;  ///< set when the pose comes from a hole of the STEP model
};

/// One square fiducial marker of a layout. Marker frame (OpenCV ArUco convention): origin at the marker
/// centre, x to the right of the printed image, y up, z out of the printed face.
struct Marker {
  int id = 0;           ///< id in the layout's dictionary, >= 0
  double size_m = 0.0;  ///< side length of the black square, m, > 0
  Eigen::Isometry3d pose_entity_marker = Eigen::Isometry3d::Identity();
};

/// The fiducial markers fixed on an entity, all from one dictionary.
struct MarkerLayout {
  std::string dictionary;  ///< OpenCV ArUco dictionary name, e.g. "DICT_4X4_50"
  std::vector<Marker> items;
};

/// A flat calibration board carried by a robot's tool: a box of size_m whose frame is at its centre, z out
/// of the printed face; its markers lie on that face (z = thickness / 2, their z along the board's z).
struct CalibrationBoard {
  Eigen::Isometry3d pose_tool_board = Eigen::Isometry3d::Identity();  ///< the mount, in the tool frame
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();                   ///< width, height, thickness, m
  MarkerLayout markers;                                               ///< in the board's frame
};

/// An OpenCV predefined marker dictionary.
struct MarkerDictionary {
  int opencv_id = 0;  ///< cv::aruco::PREDEFINED_DICTIONARY_NAME value
  int size = 0;       ///< number of markers; ids are 0 .. size-1
};

/// The predefined dictionary of this name (e.g. "DICT_4X4_50"); std::nullopt for an unknown name.
std::optional<MarkerDictionary> marker_dictionary(std::string_view name);

/// Where this entity goes when it is inserted: its pose in the target entity's frame.
struct Insertion {
  std::string target;  ///< id of the target entity
  Eigen::Isometry3d pose_target_entity = Eigen::Isometry3d::Identity();
  std::optional<CadRule> cad;  ///< set when the pose comes from mating faces of the two STEP models
};

/// CAD features of an entity. Feature ids (grasp frames, approach waypoints, screw holes and
/// "rope_attachment") are unique within one entity.
struct CadFeatures {
  std::optional<Eigen::Isometry3d> rope_attachment;  ///< pose_entity_attachment, where the crane rope hooks
  std::vector<NamedPose> grasp_frames;
  std::vector<NamedPose> approach_waypoints;
  std::vector<ScrewHole> screw_holes;
  std::optional<MarkerLayout> markers;
  std::optional<Insertion> insertion;

  /// True when no feature is defined.
  bool empty() const;
  /// The first CAD rule whose pose has not been derived yet (its pointer in the cell file), or nullptr.
  const CadRule* pending_cad() const;
  /// The pose (in the entity's frame) of the named grasp frame, approach waypoint, screw hole or
  /// "rope_attachment"; std::nullopt when there is no such feature.
  std::optional<Eigen::Isometry3d> find_pose(std::string_view feature_id) const;
};

/// The geometric model of an object (what the CAD model says about its shape and mass).
struct ObjectModel {
  /// "box" (a box of size_m), or empty: the geometry is the STEP model's solids (then `step` is set).
  std::string shape;
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();  ///< box extents along x, y, z, m (zero without a box)
  std::optional<double> mass_kg;                     ///< > 0 when given
  /// > 0 when given (never with mass_kg): the mass is the STEP model's volume times this.
  std::optional<double> density_kg_m3;
  std::string frame;                                 ///< where the entity frame sits on the model, in words
  bool is_static = false;                            ///< fixed to the floor (a target fixture)
  /// The object's STEP model ("step"), relative to the cell file's folder; empty when none. Its frame is
  /// the entity frame (docs/cad.md).
  std::string step;
  /// Hex sha256 (lower case) of the STEP file's bytes ("sha256", with `step`); empty when not pinned. When
  /// set, every reader of the model uses exactly these bytes: other bytes under `step` are refused
  /// (stale_model_problem), so a revision means the same geometry on every host.
  std::string step_sha256;
};

/// Empty when `model` pins no bytes (no step_sha256) or `actual_sha256` (hex sha256 of the bytes read
/// under `model.step`) is the pinned one; otherwise the CAD_STALE_MODEL problem naming both digests.
std::string stale_model_problem(const ObjectModel& model, std::string_view actual_sha256);

/// A camera's intrinsics as in sensor_msgs/CameraInfo: a pinhole with OpenCV's lens distortion. The one
/// camera model of the project (cell file, world model, simulated camera, tracker). Pixel (0, 0) is the
/// centre of the top-left pixel; the optical frame has z forward, x right, y down.
struct CameraIntrinsics {
  int width_px = 0;
  int height_px = 0;
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
  /// None (an ideal pinhole), or 4, 5, 8, 12 or 14 coefficients in OpenCV's order
  /// k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]: plumb_bob is 5, the rational model 8.
  std::vector<double> distortion;
  double rate_hz = 0.0;       ///< frame rate, > 0
  double noise_stddev = 0.0;  ///< simulated image noise (grey levels), >= 0
  std::string optical_frame;  ///< axis convention of the camera frame, in words

  /// An ideal pinhole (no distortion) of the given size, focal length and principal point.
  static CameraIntrinsics pinhole(int width_px, int height_px, double f_px, double cx_px, double cy_px) {
    CameraIntrinsics c;
    c.width_px = width_px;
    c.height_px = height_px;
    c.fx_px = c.fy_px = f_px;
    c.cx_px = cx_px;
    c.cy_px = cy_px;
    return c;
  }
  /// The 3x3 camera matrix K.
  Eigen::Matrix3d camera_matrix() const;
  /// Where a point in the optical frame (z > 0) lands on the ideal pinhole image, in pixels (no distortion).
  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const {
    return {fx_px * point_camera.x() / point_camera.z() + cx_px, fy_px * point_camera.y() / point_camera.z() + cy_px};
  }
};

/// Rotation R = Rz(yaw) Ry(pitch) Rx(roll) from roll, pitch, yaw in degrees (the cell file's `rpy_deg`).
Eigen::Matrix3d rotation_from_rpy_deg(const Eigen::Vector3d& rpy_deg);
/// Pose from a position (m) and roll-pitch-yaw angles (deg) as in the cell file.
Eigen::Isometry3d pose_from_position_rpy_deg(const Eigen::Vector3d& position_m, const Eigen::Vector3d& rpy_deg);

}  // namespace rigger::cell
