#include "mesh_points.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>

namespace rigger::perception::detail {

void check_mesh(const Mesh& mesh) {
  if (mesh.triangles.empty()) {
    throw std::invalid_argument("perception mesh: no triangles");
  }
  const int n = static_cast<int>(mesh.vertices_m.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    if (tri.minCoeff() < 0 || tri.maxCoeff() >= n) {
      throw std::invalid_argument("perception mesh: triangle " + std::to_string(t) + " indexes a vertex outside 0.." +
                                  std::to_string(n - 1));
    }
  }
}

SurfacePoints sample_surface(const Mesh& mesh, int count) {
  std::vector<double> cumulative_area;
  cumulative_area.reserve(mesh.triangles.size());
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices_m[t[0]];
    total += 0.5 * (mesh.vertices_m[t[1]] - a).cross(mesh.vertices_m[t[2]] - a).norm();
    cumulative_area.push_back(total);
  }
  SurfacePoints out;
  if (total <= 0.0) {
    return out;
  }
  // A fixed seed: the model, and so every result for a frame, is reproducible.
  std::mt19937_64 random(20231);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < count; ++i) {
    // Stratified along the cumulative area, so that the points cover the surface evenly.
    const double at = (i + unit(random)) / count * total;
    const auto k = static_cast<std::size_t>(
        std::min<std::ptrdiff_t>(std::lower_bound(cumulative_area.begin(), cumulative_area.end(), at) -
                                     cumulative_area.begin(),
                                 static_cast<std::ptrdiff_t>(cumulative_area.size()) - 1));
    const Eigen::Vector3i& t = mesh.triangles[k];
    const Eigen::Vector3d& a = mesh.vertices_m[t[0]];
    const Eigen::Vector3d& b = mesh.vertices_m[t[1]];
    const Eigen::Vector3d& c = mesh.vertices_m[t[2]];
    double u = unit(random);
    double v = unit(random);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.squaredNorm() == 0.0) {
      continue;
    }
    out.points_m.push_back(a + u * (b - a) + v * (c - a));
    out.normals.push_back(normal.normalized());
  }
  return out;
}

PointIndex::PointIndex(const std::vector<Eigen::Vector3d>& points_m)
    : data_(static_cast<int>(points_m.size()), 3, CV_32F) {
  for (int i = 0; i < data_.rows; ++i) {
    for (int j = 0; j < 3; ++j) {
      data_.at<float>(i, j) = static_cast<float>(points_m[static_cast<std::size_t>(i)][j]);
    }
  }
  if (data_.rows > 0) {
    index_ = std::make_unique<cv::flann::Index>(data_, cv::flann::KDTreeIndexParams(1));
  }
}

int PointIndex::nearest(const Eigen::Vector3d& query_m, double& squared_distance_m2) const {
  if (!index_) {
    return -1;
  }
  const float q[3] = {static_cast<float>(query_m.x()), static_cast<float>(query_m.y()), static_cast<float>(query_m.z())};
  int index = -1;
  float distance = 0.0F;
  cv::Mat query(1, 3, CV_32F, const_cast<float*>(q));
  cv::Mat indices(1, 1, CV_32S, &index);
  cv::Mat distances(1, 1, CV_32F, &distance);
  // One leaf checked per tree is exact for a single k-d tree only approximately; 32 checks keep
  // it nearly exact at a small cost.
  index_->knnSearch(query, indices, distances, 1, cv::flann::SearchParams(32));
  squared_distance_m2 = distance;
  return index;
}

}  // namespace rigger::perception::detail
