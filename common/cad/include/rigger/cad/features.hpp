#pragma once
/// @file
/// The faces, edges and vertices of a model with stable references, and the features classified from
/// them (planar faces, cylindrical faces, holes, line and circular edges, vertices). Lengths in metres,
/// directions unit vectors in the model's frame. Indices are 0-based positions in OCCT's
/// TopExp::MapShapes order, which is stable for the same file.

#include "rigger/cad/model.hpp"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace rigger::cad {

enum class EntityKind { kFace, kEdge, kVertex };
std::string_view to_string(EntityKind kind);

/// What an entity looks like, independent of its index: detects a reference into an edited model.
/// type: "plane", "cylinder", "cone", "sphere", "torus", "bspline", "other" (faces); "line", "circle",
/// "other", "degenerate" (edges); "vertex". direction: a plane's outward normal, a cylinder's, cone's or
/// circle's axis, a line's direction (axes and lines with a canonical sign: first non-zero component
/// positive); zero when none. radius_m: cylinders, circles, spheres; 0 otherwise. A B-spline or Bezier
/// face or edge within 0.01 mm of a plane, cylinder, line or circle has that type (and `recognised`
/// set), its direction and radius from the fitted shape: the signature of the analytic one.
struct Signature {
  std::string type;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

/// True when the two signatures agree within `tolerance_m` (positions, radii) and `tolerance_rad`.
bool same_signature(const Signature& a, const Signature& b, double tolerance_m = 1e-6, double tolerance_rad = 1e-6);

/// A reference to one face, edge or vertex: the model it was taken from, its index and its signature.
struct Reference {
  std::string model_sha256;
  EntityKind kind = EntityKind::kFace;
  int index = -1;
  Signature signature;
};

struct FaceInfo {
  int index = -1;
  Signature signature;       ///< type, centroid, normal/axis, radius
  double area_m2 = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< planes: outward normal
  Eigen::Vector3d axis_point_m = Eigen::Vector3d::Zero();  ///< cylinders: a point on the axis
  bool material_outside = false;  ///< cylinders: concave (the material surrounds the axis)
  double angle_rad = 0.0;         ///< cylinders: angular span of the face
  double axial_min = 0.0, axial_max = 0.0;  ///< cylinders: extent along `signature.direction` from axis_point_m
  int solid = -1;                 ///< index of the solid holding the face (-1: none)
  bool recognised = false;        ///< a B-spline or Bezier face taken for the plane or cylinder of its signature
};

struct EdgeInfo {
  int index = -1;
  Signature signature;
  double length_m = 0.0;
  Eigen::Vector3d start_m = Eigen::Vector3d::Zero();  ///< first vertex (edge orientation)
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();
  bool recognised = false;  ///< a B-spline or Bezier edge taken for the line or circle of its signature
};

struct VertexInfo {
  int index = -1;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
};

/// A hole: a group of coaxial cylindrical faces of one radius whose material is outside and that close
/// the full circle. axis points out of the hole (from its bottom to its entry); entry_m is on the axis at
/// the open end (for a through hole: the end whose outward axis has the larger z, then y, then x);
/// depth_m is the length along the axis.
struct Hole {
  int index = -1;
  std::vector<int> faces;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d entry_m = Eigen::Vector3d::Zero();
  double diameter_m = 0.0;
  double depth_m = 0.0;
  bool through = false;
};

/// Everything classify() finds in a model.
struct Features {
  std::string model_sha256;
  std::vector<FaceInfo> faces;
  std::vector<EdgeInfo> edges;
  std::vector<VertexInfo> vertices;
  std::vector<Hole> holes;
  int solids = 0;

  int count_faces(const std::string& type) const;
  int count_edges(const std::string& type) const;
  /// A reference to entity `index` of `kind`; throws CadError(kBadReference) when out of range.
  Reference reference(EntityKind kind, int index) const;
  const Signature& signature(EntityKind kind, int index) const;
};

/// Classifies every face, edge and vertex of `model` and groups the holes.
Features classify(const Model& model);

/// The index `ref` designates in `features`. The index is kept when its signature still matches; when
/// the model changed and exactly one other entity of the kind has the same signature, that one is
/// returned; otherwise throws StaleReference saying what differs (or kBadReference).
int resolve(const Features& features, const Reference& ref, double tolerance_m = 1e-6, double tolerance_rad = 1e-6);

}  // namespace rigger::cad
