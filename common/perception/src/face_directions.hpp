#pragma once
// Orientations from the directions of a part's faces: the image's dominant surface normals matched with
// the model's, so that the search starts from orientations a few degrees off at most, not from a
// sampling of all orientations about 18 degrees apart.

#include <Eigen/Geometry>

#include <vector>

#include "depth_grid.hpp"
#include "mesh_points.hpp"

namespace rigger::perception::detail {

/// A dominant direction among normals: their mean within a cone, and its share of all of them.
struct FaceDirection {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double share = 0.0;
  /// Where the planes of this direction lie (normal · point), each holding at least a fifth of its points.
  std::vector<double> offsets_m;
};

/// The dominant directions of `normals` (unit vectors), largest first: each the mean of the normals within
/// 10 degrees of the one with the most such neighbours, those within 20 degrees then set aside; at most
/// `max_directions`, each holding at least `min_share` of the normals.
std::vector<FaceDirection> face_directions(const std::vector<Eigen::Vector3d>& points_m,
                                           const std::vector<Eigen::Vector3d>& normals, double min_share,
                                           int max_directions);

/// An orientation from matched directions: the model directions turned onto the image's (indices into
/// each list; `second` -1 for one direction matched).
struct FaceMatch {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  int image_first = 0;
  int model_first = 0;
  int image_second = -1;
  int model_second = -1;
};

/// The positions (object to camera) of `match.rotation` that put the matched model planes on the
/// image's, each nearest `start` (one per combination of the model's planes of the matched directions).

/// Rotations (object to camera) that turn model directions onto the image's: the image's two largest
/// directions onto every pair of model directions at the same angle to each other (within 10 degrees),
/// the first exactly; with one image direction only, every model direction onto it at `turns` turns
/// about it. Each turned model direction faces the camera as the image's does.
std::vector<Eigen::Vector3d> positions_on_planes(const FaceMatch& match, const std::vector<FaceDirection>& image,
                                                 const std::vector<FaceDirection>& model, const Eigen::Vector3d& start);

std::vector<FaceMatch> orientations_from_faces(const std::vector<FaceDirection>& image,
                                               const std::vector<FaceDirection>& model, int turns);

/// The pose with orientation `rotation` whose camera-facing `points` have their centroid at `centroid_camera_m`.
Eigen::Isometry3d placed(const SurfacePoints& points, const Eigen::Matrix3d& rotation,
                         const Eigen::Vector3d& centroid_camera_m);

/// The search's candidates on one surface of the image: its dominant face directions (at most `image_faces`,
/// each with `min_share` of its normals) matched with the model's (`model_faces`, object frame), each
/// orientation placed with its matched faces on the image's planes, starting from `placed` with `points`;
/// empty when no direction matches.
std::vector<Eigen::Isometry3d> face_hypotheses(const DepthGrid& grid, const Surface& surface,
                                               const std::vector<FaceDirection>& model_faces,
                                               const SurfacePoints& points, double min_share, int image_faces,
                                               int turns);

}  // namespace rigger::perception::detail
