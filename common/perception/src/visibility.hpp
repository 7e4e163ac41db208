#pragma once
// What the depth image shows of a part's camera-facing points at a pose: seen, seen through, or where the
// image has no depth.

#include "depth_grid.hpp"
#include "mesh_points.hpp"

namespace rigger::perception::detail {

// A point of a face seen further than 70 degrees from its normal lands, moved along the part, on the
// faces next to it at nearly their depth: no evidence of where the part ends (cosine).
constexpr double kSquarelyFacing = 0.34;
// An image normal this near a model point's (cosine: 53 degrees) is of the same face.
constexpr double kSameFace = 0.6;
// A model point is seen where the depth image is within this of it.
constexpr double kSeenM = 0.015;

/// How well the image shows the points facing the camera: +1 where it sees the point, -1 where it
/// sees through it (farther), 0 where something nearer hides it or nothing is seen. Seen: on a valid
/// cell (a normal, above the support), or with `any_depth` on any depth at the point's distance unless
/// the cell's normal says it is another face (and then only points within 70 degrees of their normal).
double visibility_score(const DepthGrid& grid, const SurfacePoints& points, const Eigen::Isometry3d& pose,
                        int* supported = nullptr, int* seen_through = nullptr, bool any_depth = false);

/// Of the points facing the camera within 70 degrees of their normal and in view, the shares (weighted by how
/// squarely they face) that land where the image has no depth, and behind something nearer.
struct FacingShares {
  /// Of those not hidden: 1 when none is in view. The tracker's check of a pose slid into a strip without
  /// depth, on the localizer's samples.
  double unseen = 1.0;
  /// Of all in view: a part fitted behind the surface it was fitted to hides much of itself there.
  double hidden = 0.0;
};
FacingShares facing_shares(const DepthGrid& grid, const SurfacePoints& points, const Eigen::Isometry3d& pose);

}  // namespace rigger::perception::detail
