#pragma once
// Planes, cylinders, lines and circles written as B-spline or Bezier geometry, recognised by fitting the
// analytic shape to points sampled on the face or edge. Internal to rigger_cad.

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <Eigen/Core>
#include <TopoDS_Shape.hxx>

#include <optional>

namespace rigger::cad::detail {

/// How far (m) every sample of a B-spline or Bezier face or edge may lie from the fitted plane, cylinder,
/// line or circle for it to be taken for one: 0.01 mm, absolute.
constexpr double kRecognitionTolerance_m = 1e-5;
/// How far (rad) every sampled normal of a face may turn from the fitted plane's or cylinder's there.
constexpr double kRecognitionTolerance_rad = 1e-3;

/// A plane through `point_m` with unit `normal` (the sign is arbitrary).
struct FittedPlane {
  Eigen::Vector3d point_m;
  Eigen::Vector3d normal;
};

/// A cylinder: unit `axis` through `axis_point_m` (the point of the axis nearest the samples' mean); the
/// face spans `angle_rad` about the axis and [axial_min, axial_max] along it from axis_point_m.
struct FittedCylinder {
  Eigen::Vector3d axis_point_m;
  Eigen::Vector3d axis;
  double radius_m;
  double angle_rad;
  double axial_min, axial_max;
};

/// A line along unit `direction` (start to end of the edge's parameter range).
struct FittedLine {
  Eigen::Vector3d direction;
};

/// A circle (or an arc of it) about `centre_m` with unit `axis` normal to its plane.
struct FittedCircle {
  Eigen::Vector3d centre_m;
  Eigen::Vector3d axis;
  double radius_m;
};

/// Whether B-spline or Bezier `surface` (restricted to its face's parameter bounds) is a plane, or a
/// cylinder, within kRecognitionTolerance_m and kRecognitionTolerance_rad. Any other surface type:
/// nullopt. A plane is never taken for a cylinder.
std::optional<FittedPlane> fit_plane(const BRepAdaptor_Surface& surface);
std::optional<FittedCylinder> fit_cylinder(const BRepAdaptor_Surface& surface);

/// Whether B-spline or Bezier `curve` is a straight line, or a circle, within kRecognitionTolerance_m.
std::optional<FittedLine> fit_line(const BRepAdaptor_Curve& curve);
std::optional<FittedCircle> fit_circle(const BRepAdaptor_Curve& curve);

/// Whether `point_m` is outside `solid`, from the first face the ray from it along unit `direction` crosses
/// (inside when the ray leaves the material there; outside when it crosses none or enters). nullopt when
/// the ray first meets a face on its boundary or tangentially: ask OCCT's solid classifier. For B-spline
/// solids, on which the classifier spends about a second per point on its ray's extrema with every edge.
std::optional<bool> outside_along(const TopoDS_Shape& solid, const Eigen::Vector3d& point_m,
                                  const Eigen::Vector3d& direction);

}  // namespace rigger::cad::detail
