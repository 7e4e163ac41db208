#pragma once
// The depth image as an organized grid of camera-frame points with normals (at a pixel stride), its
// connected surfaces, and projection of points into it: the scene side of localization.

#include "rigger/perception/localize.hpp"

#include "mesh_points.hpp"

#include <cstdint>
#include <vector>

namespace rigger::perception::detail {

/// One connected surface of the grid: its cells, centroid and spread (camera frame, metres).
struct Surface {
  std::vector<int> cells;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;  ///< largest distance of a cell from the centroid
};

class DepthGrid {
 public:
  /// Cells about `max_cells` in number. Pixels at or below `min_height_world_m` (if set) are support:
  /// not valid, but their depth still counts as seen (free space) in visible_support().
  DepthGrid(const DepthFrame& frame, int max_cells, const std::optional<double>& min_height_world_m);

  int finite_pixels() const { return finite_pixels_; }
  int valid_cells() const { return valid_cells_; }
  bool valid(int cell) const { return valid_[static_cast<std::size_t>(cell)] != 0; }
  const Eigen::Vector3d& point(int cell) const { return points_[static_cast<std::size_t>(cell)]; }
  const Eigen::Vector3d& normal(int cell) const { return normals_[static_cast<std::size_t>(cell)]; }
  /// Depth seen at the cell (support included), NaN for none.
  float seen_z(int cell) const { return seen_z_[static_cast<std::size_t>(cell)]; }

  /// The cell a camera-frame point projects to, -1 outside the image or behind the camera.
  int cell_of(const Eigen::Vector3d& point_camera_m) const;

  /// Connected surfaces of valid cells (neighbours closer than a gap), largest first, each of at
  /// least `min_cells`.
  std::vector<Surface> surfaces(int min_cells) const;

 private:
  int cols_ = 0;
  int rows_ = 0;
  int stride_ = 1;
  int finite_pixels_ = 0;
  int valid_cells_ = 0;
  DepthIntrinsics k_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<float> seen_z_;
  std::vector<std::uint8_t> valid_;
};

/// The cells of `surfaces` whose points lie within the box [low, high] of a part's frame (`object_camera`:
/// camera to part), with their centroid: what a part is refined on and judged on near a pose, whatever
/// touches it.
Surface within_box(const DepthGrid& grid, const std::vector<Surface>& surfaces, const Eigen::Isometry3d& object_camera,
                   const Eigen::Vector3d& low, const Eigen::Vector3d& high);

// The cells of one surface of the image, indexed for nearest-point search.
struct SurfaceIndex {
  std::vector<int> cells;
  PointIndex index;

  static std::vector<Eigen::Vector3d> points_of(const DepthGrid& grid, const std::vector<int>& cells) {
    std::vector<Eigen::Vector3d> points;
    points.reserve(cells.size());
    for (const int cell : cells) {
      points.push_back(grid.point(cell));
    }
    return points;
  }
  SurfaceIndex(const DepthGrid& grid, const Surface& surface)
      : cells(surface.cells), index(points_of(grid, surface.cells), 0.01) {}
};

}  // namespace rigger::perception::detail
