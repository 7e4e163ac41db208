#include "visibility.hpp"

#include <cmath>

namespace rigger::perception::detail {

double visibility_score(const DepthGrid& grid, const SurfacePoints& points, const Eigen::Isometry3d& pose,
                        int* supported, int* seen_through, bool any_depth) {
  double score = 0.0;
  for (std::size_t i = 0; i < points.points_m.size(); ++i) {
    const Eigen::Vector3d p = pose * points.points_m[i];
    const double facing = -(pose.linear() * points.normals[i]).dot(p);
    if (facing <= (any_depth ? kSquarelyFacing * p.norm() : 0.0)) {
      continue;
    }
    const int cell = grid.cell_of(p);
    const float seen = cell < 0 ? std::nanf("") : grid.seen_z(cell);
    if (!std::isfinite(seen)) {
      continue;
    }
    if (seen > p.z() + kSeenM) {
      score -= 1.0;
      seen_through && ++*seen_through;
    } else if (seen > p.z() - kSeenM && (any_depth || grid.valid(cell))) {
      if (any_depth && grid.valid(cell) && grid.normal(cell).dot(pose.linear() * points.normals[i]) < kSameFace) {
        continue;  // another face at nearly the point's depth: the one next to a fold
      }
      score += 1.0;
      supported && ++*supported;
    }
  }
  return score;
}

FacingShares facing_shares(const DepthGrid& grid, const SurfacePoints& points, const Eigen::Isometry3d& pose) {
  double seen = 0.0;
  double unseen = 0.0;
  double hidden = 0.0;
  for (std::size_t i = 0; i < points.points_m.size(); ++i) {
    const Eigen::Vector3d p = pose * points.points_m[i];
    const double facing = -(pose.linear() * points.normals[i]).dot(p) / p.norm();
    const int cell = facing > kSquarelyFacing ? grid.cell_of(p) : -1;
    if (cell < 0) {
      continue;
    }
    const float z = grid.seen_z(cell);
    if (!std::isfinite(z)) {
      unseen += facing;
    } else if (z > p.z() - kSeenM) {
      seen += facing;
    } else {
      hidden += facing;
    }
  }
  FacingShares shares;
  if (seen + unseen > 0.0) {
    shares.unseen = unseen / (seen + unseen);
    shares.hidden = hidden / (seen + unseen + hidden);
  }
  return shares;
}

}  // namespace rigger::perception::detail
