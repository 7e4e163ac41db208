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

double surface_area(const Mesh& mesh) {
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices_m[t[0]];
    total += 0.5 * (mesh.vertices_m[t[1]] - a).cross(mesh.vertices_m[t[2]] - a).norm();
  }
  return total;
}

Eigen::Vector3d surface_centroid(const Mesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices_m[t[0]];
    const Eigen::Vector3d& b = mesh.vertices_m[t[1]];
    const Eigen::Vector3d& c = mesh.vertices_m[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    sum += area * (a + b + c) / 3.0;
    total += area;
  }
  return total > 0.0 ? Eigen::Vector3d(sum / total) : Eigen::Vector3d::Zero();
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
  // Outward normals whichever way the triangles wind: a closed surface wound the other way round
  // encloses a negative volume.
  double volume6 = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    volume6 += mesh.vertices_m[t[0]].dot(mesh.vertices_m[t[1]].cross(mesh.vertices_m[t[2]]));
  }
  const double outward = volume6 < 0.0 ? -1.0 : 1.0;
  // A fixed seed: the model, and so every result for a frame, is reproducible.
  std::mt19937_64 random(20231);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < count; ++i) {
    // Stratified along the cumulative area, so that the points cover the surface evenly.
    const double at = (i + unit(random)) / count * total;
    const auto k = static_cast<std::size_t>(std::min<std::ptrdiff_t>(
        std::lower_bound(cumulative_area.begin(), cumulative_area.end(), at) - cumulative_area.begin(),
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
    out.normals.push_back(outward * normal.normalized());
  }
  return out;
}

PointIndex::PointIndex(const std::vector<Eigen::Vector3d>& points_m, double cell_m) : cell_m_(cell_m) {
  if (points_m.empty() || !(cell_m > 0.0)) {
    return;
  }
  Eigen::Vector3d low = points_m.front();
  Eigen::Vector3d high = low;
  for (const Eigen::Vector3d& p : points_m) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  origin_m_ = low;
  cells_ = ((high - low) / cell_m).array().floor().cast<int>() + 1;
  const auto cell_of = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3i c = ((p - origin_m_) / cell_m_).array().floor().cast<int>().min(cells_.array() - 1);
    return (c.z() * cells_.y() + c.y()) * cells_.x() + c.x();
  };
  cell_start_.assign(static_cast<std::size_t>(cells_.prod()) + 1, 0);
  for (const Eigen::Vector3d& p : points_m) {
    ++cell_start_[static_cast<std::size_t>(cell_of(p)) + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) {
    cell_start_[c] += cell_start_[c - 1];
  }
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  points_m_.resize(points_m.size());
  original_.resize(points_m.size());
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const auto at = static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_of(points_m[i]))]++);
    points_m_[at] = points_m[i];
    original_[at] = static_cast<int>(i);
  }
}

int PointIndex::nearest(const Eigen::Vector3d& query_m, int k, int* indices, double* squared_distances_m2) const {
  k = std::min(k, 8);
  if (points_m_.empty() || k < 1) {
    return 0;
  }
  const Eigen::Vector3i centre = ((query_m - origin_m_) / cell_m_).array().floor().cast<int>();
  int found = 0;
  for (int z = std::max(0, centre.z() - 1); z <= std::min(cells_.z() - 1, centre.z() + 1); ++z) {
    for (int y = std::max(0, centre.y() - 1); y <= std::min(cells_.y() - 1, centre.y() + 1); ++y) {
      for (int x = std::max(0, centre.x() - 1); x <= std::min(cells_.x() - 1, centre.x() + 1); ++x) {
        const auto cell = static_cast<std::size_t>((z * cells_.y() + y) * cells_.x() + x);
        for (int i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
          const double d2 = (points_m_[static_cast<std::size_t>(i)] - query_m).squaredNorm();
          if (found == k && d2 >= squared_distances_m2[k - 1]) {
            continue;
          }
          // Insertion into the sorted list of the k nearest so far.
          int at = found < k ? found++ : k - 1;
          while (at > 0 && squared_distances_m2[at - 1] > d2) {
            squared_distances_m2[at] = squared_distances_m2[at - 1];
            indices[at] = indices[at - 1];
            --at;
          }
          squared_distances_m2[at] = d2;
          indices[at] = original_[static_cast<std::size_t>(i)];
        }
      }
    }
  }
  return found;
}

}  // namespace rigger::perception::detail
