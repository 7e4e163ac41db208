#pragma once
// Turns of a part: the orientations the search tries, and the turns that map the part onto itself.

#include "mesh_points.hpp"

#include <functional>
#include <string>

namespace rigger::perception::detail {

/// Rotations spread over all orientations: a Fibonacci sphere of `directions` for the object's z axis,
/// each with `turns` turns about it.
std::vector<Eigen::Matrix3d> orientation_samples(int directions, int turns);

/// A turn about the object's axes through its centre that maps its surface onto itself.
struct Turn {
  Eigen::Isometry3d about_centre = Eigen::Isometry3d::Identity();  ///< object frame
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::string name;  ///< e.g. "2-fold about x"
};

/// The half turns about x, y and z and the quarter turn about z (through `centre_m`) that map every
/// third of `points` within `tolerance_m` of the surface (`distance` from a point, object frame). Near an
/// edge a turned point may have only the next face's samples near it, a few millimetres off its face: up to
/// 1 % of the points may be off by up to three times the tolerance. A real feature the turn does not map (a
/// blind hole, a notch, a bump) puts points much farther off.
std::vector<Turn> turns_onto_itself(const SurfacePoints& points,
                                    const std::function<double(const Eigen::Vector3d&)>& distance,
                                    const Eigen::Vector3d& centre_m, double tolerance_m);

}  // namespace rigger::perception::detail
