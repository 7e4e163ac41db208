#pragma once
/// @file
/// Frames from picks (the paper's programming rules). Poses are in the model's frame, metres. Every
/// function throws CadError(kNotAFrame) saying why the picks cannot make a frame, or kBadReference.

#include "rigger/cad/features.hpp"

#include <Eigen/Geometry>

namespace rigger::cad {

struct FrameTolerances {
  double perpendicular_rad = 1e-3;  ///< |angle between the edges - 90°|
  double on_face_m = 5e-4;          ///< distance of a picked point from its face (picks come from a mesh)
};

/// The paper's rule: origin at `point_m`, x along the first edge (from its first to its last vertex),
/// y along the second, z = x × y. Both edges must be straight lines and perpendicular.
Eigen::Isometry3d frame_from_edges(const Features& features, const Eigen::Vector3d& point_m, int edge_x, int edge_y,
                                   const FrameTolerances& tolerances = {});

/// Origin at the point of face `face` nearest to `point_m` (which must lie on the face), z along the
/// face's outward normal there, x the model's x projected onto the tangent plane (y when x is normal).
Eigen::Isometry3d frame_from_face(const Model& model, const Features& features, int face,
                                  const Eigen::Vector3d& point_m, const FrameTolerances& tolerances = {});

/// Origin at the hole's entry, z along its axis (out of the hole), x as for faces.
Eigen::Isometry3d frame_from_hole(const Features& features, int hole);

/// Where a sling hooks a part so that it hangs level: origin `clearance_m` above the model's highest point,
/// straight above its centre of mass (uniform density, over its solids), axes the model's (z up when the
/// part stands as modelled). Throws CadError(kNotAFrame) when the model has no volume (no solid).
Eigen::Isometry3d frame_above_centre_of_mass(const Model& model, double clearance_m);

/// A right-handed rotation with the given z and x = `x_hint` projected onto the plane normal to z
/// (model y when x_hint is parallel to z).
Eigen::Matrix3d rotation_from_z(const Eigen::Vector3d& z, const Eigen::Vector3d& x_hint = Eigen::Vector3d::UnitX());

}  // namespace rigger::cad
