#pragma once
// Points with normals on a mesh's surface, and distances to that surface.

#include "rigger/perception/localize.hpp"

#include <opencv2/flann.hpp>

#include <memory>

namespace rigger::perception::detail {

/// Points on the surface with their outward normals (the triangles' winding, counter-clockwise
/// seen from outside), metres.
struct SurfacePoints {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<Eigen::Vector3d> normals;
};

/// Throws std::invalid_argument (naming the triangle) for an index out of range or no triangles.
void check_mesh(const Mesh& mesh);

/// `count` points spread by area (deterministic: the same mesh gives the same points).
SurfacePoints sample_surface(const Mesh& mesh, int count);

/// Nearest neighbours among fixed points (a FLANN k-d tree over a float copy).
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Eigen::Vector3d>& points_m);
  /// Index of the nearest point and the squared distance; -1 for an empty index.
  int nearest(const Eigen::Vector3d& query_m, double& squared_distance_m2) const;

 private:
  cv::Mat data_;
  std::unique_ptr<cv::flann::Index> index_;
};

}  // namespace rigger::perception::detail
