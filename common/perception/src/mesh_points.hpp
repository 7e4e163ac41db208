#pragma once
// Points with normals on a mesh's surface, and distances to that surface.

#include "rigger/perception/localize.hpp"

namespace rigger::perception::detail {

/// Points on the surface with their outward normals, metres. For a closed surface the normals point
/// out whichever way its triangles wind (the sign of the enclosed volume says which way that is).
struct SurfacePoints {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<Eigen::Vector3d> normals;
};

/// Throws std::invalid_argument (naming the triangle) for an index out of range or no triangles.
void check_mesh(const Mesh& mesh);

/// Total area of the triangles, square metres.
double surface_area(const Mesh& mesh);

/// Area-weighted centroid of the triangles, metres.
Eigen::Vector3d surface_centroid(const Mesh& mesh);

/// `count` points spread by area (deterministic: the same mesh gives the same points).
SurfacePoints sample_surface(const Mesh& mesh, int count);

/// Nearest neighbours among fixed points, exact within `cell_m` of the query: the points sorted
/// into cubic cells of that size, and the 27 cells around the query searched.
class PointIndex {
 public:
  PointIndex(const std::vector<Eigen::Vector3d>& points_m, double cell_m);
  /// Indices of the `k` (at most 8) nearest points within one cell's reach, nearest first, and their
  /// squared distances; the number found (0 when no point is that near).
  int nearest(const Eigen::Vector3d& query_m, int k, int* indices, double* squared_distances_m2) const;

 private:
  std::vector<Eigen::Vector3d> points_m_;  // sorted by cell
  std::vector<int> original_;              // index into the points given
  std::vector<int> cell_start_;            // per cell, then one past the end
  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i cells_ = Eigen::Vector3i::Zero();
  double cell_m_ = 0.0;
};

}  // namespace rigger::perception::detail
