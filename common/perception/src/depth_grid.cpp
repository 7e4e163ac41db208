#include "depth_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rigger::perception::detail {

namespace {

// Neighbours further apart than this are across a depth edge: no normal there, no connection.
constexpr double kEdgeGapM = 0.015;
// Normals from the neighbours this many cells away on each side: a wider baseline than one pixel
// averages the sensor's depth noise (millimetres at a metre and a half) out of the normal.
constexpr int kNormalReach = 2;

}  // namespace

DepthGrid::DepthGrid(const DepthFrame& frame, int max_cells, const std::optional<double>& min_height_world_m)
    : k_(frame.intrinsics) {
  const cv::Mat& depth = frame.depth_m;
  stride_ = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(depth.total()) / max_cells))));
  cols_ = (depth.cols + stride_ - 1) / stride_;
  rows_ = (depth.rows + stride_ - 1) / stride_;
  const auto n = static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  points_.assign(n, Eigen::Vector3d::Constant(nan));
  normals_.assign(n, Eigen::Vector3d::Zero());
  seen_z_.assign(n, std::numeric_limits<float>::quiet_NaN());
  valid_.assign(n, 0);
  std::vector<std::uint8_t> above(n, 0);
  for (int r = 0; r < rows_; ++r) {
    const float* row = depth.ptr<float>(r * stride_);
    for (int c = 0; c < cols_; ++c) {
      const int u = c * stride_;
      const float z = row[u];
      if (!std::isfinite(z) || z <= 0.0F) {
        continue;
      }
      ++finite_pixels_;
      const auto i = static_cast<std::size_t>(r * cols_ + c);
      seen_z_[i] = z;
      const Eigen::Vector3d p((u - k_.cx_px) / k_.fx_px * z, (r * stride_ - k_.cy_px) / k_.fy_px * z, z);
      points_[i] = p;
      above[i] = !min_height_world_m || (frame.pose_world_camera * p).z() > *min_height_world_m;
    }
  }
  auto at = [&](int c, int r) -> const Eigen::Vector3d* {
    if (c < 0 || r < 0 || c >= cols_ || r >= rows_) {
      return nullptr;
    }
    const Eigen::Vector3d& p = points_[static_cast<std::size_t>(r * cols_ + c)];
    return std::isfinite(p.z()) ? &p : nullptr;
  };
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      const auto i = static_cast<std::size_t>(r * cols_ + c);
      if (!above[i]) {
        continue;
      }
      const Eigen::Vector3d& p = points_[i];
      const Eigen::Vector3d* left = at(c - kNormalReach, r);
      const Eigen::Vector3d* right = at(c + kNormalReach, r);
      const Eigen::Vector3d* up = at(c, r - kNormalReach);
      const Eigen::Vector3d* down = at(c, r + kNormalReach);
      const double reach_m = kEdgeGapM * kNormalReach;
      if (!left || !right || !up || !down || (*left - p).norm() > reach_m || (*right - p).norm() > reach_m ||
          (*up - p).norm() > reach_m || (*down - p).norm() > reach_m) {
        continue;  // near a depth edge: no normal to trust
      }
      Eigen::Vector3d normal = (*right - *left).cross(*down - *up);
      if (normal.squaredNorm() == 0.0) {
        continue;
      }
      normal.normalize();
      normals_[i] = normal.dot(p) > 0.0 ? -normal : normal;  // towards the camera
      valid_[i] = 1;
      ++valid_cells_;
    }
  }
}

int DepthGrid::cell_of(const Eigen::Vector3d& point_camera_m) const {
  if (point_camera_m.z() <= 1e-6) {
    return -1;
  }
  const double u = k_.fx_px * point_camera_m.x() / point_camera_m.z() + k_.cx_px;
  const double v = k_.fy_px * point_camera_m.y() / point_camera_m.z() + k_.cy_px;
  const auto c = static_cast<int>(std::lround(u / stride_));
  const auto r = static_cast<int>(std::lround(v / stride_));
  if (c < 0 || r < 0 || c >= cols_ || r >= rows_) {
    return -1;
  }
  return r * cols_ + c;
}

std::vector<Surface> DepthGrid::surfaces(int min_cells) const {
  std::vector<int> label(valid_.size(), -1);
  std::vector<Surface> out;
  std::vector<int> stack;
  for (std::size_t seed = 0; seed < valid_.size(); ++seed) {
    if (!valid_[seed] || label[seed] >= 0) {
      continue;
    }
    Surface surface;
    const int id = static_cast<int>(seed);
    label[seed] = id;
    stack.assign(1, id);
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      surface.cells.push_back(cell);
      const int c = cell % cols_;
      const int r = cell / cols_;
      const int neighbours[4][2] = {{c - 1, r}, {c + 1, r}, {c, r - 1}, {c, r + 1}};
      for (const auto& nb : neighbours) {
        if (nb[0] < 0 || nb[1] < 0 || nb[0] >= cols_ || nb[1] >= rows_) {
          continue;
        }
        const int other = nb[1] * cols_ + nb[0];
        const auto o = static_cast<std::size_t>(other);
        if (valid_[o] && label[o] < 0 && (points_[o] - point(cell)).norm() <= kEdgeGapM) {
          label[o] = id;
          stack.push_back(other);
        }
      }
    }
    if (static_cast<int>(surface.cells.size()) < min_cells) {
      continue;
    }
    for (const int cell : surface.cells) {
      surface.centroid_m += point(cell);
    }
    surface.centroid_m /= static_cast<double>(surface.cells.size());
    for (const int cell : surface.cells) {
      surface.radius_m = std::max(surface.radius_m, (point(cell) - surface.centroid_m).norm());
    }
    out.push_back(std::move(surface));
  }
  std::sort(out.begin(), out.end(), [](const Surface& a, const Surface& b) { return a.cells.size() > b.cells.size(); });
  return out;
}

Surface within_box(const DepthGrid& grid, const std::vector<Surface>& surfaces, const Eigen::Isometry3d& object_camera,
                   const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  Surface out;
  for (const Surface& surface : surfaces) {
    for (const int cell : surface.cells) {
      const Eigen::Vector3d p = object_camera * grid.point(cell);
      if ((p.array() >= low.array()).all() && (p.array() <= high.array()).all()) {
        out.cells.push_back(cell);
        out.centroid_m += grid.point(cell);
      }
    }
  }
  if (!out.cells.empty()) {
    out.centroid_m /= static_cast<double>(out.cells.size());
  }
  return out;
}

}  // namespace rigger::perception::detail
