#include "recognise.hpp"

#include "occt_util.hpp"

#include <BRep_Tool.hxx>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <IntCurvesFace_ShapeIntersector.hxx>
#include <Precision.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Lin.hxx>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rigger::cad::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = kRecognitionTolerance_m;

bool freeform(GeomAbs_SurfaceType type) {
  return type == GeomAbs_BSplineSurface || type == GeomAbs_BezierSurface;
}
bool freeform(GeomAbs_CurveType type) {
  return type == GeomAbs_BSplineCurve || type == GeomAbs_BezierCurve;
}

// Samples per parameter direction: enough to see every polynomial span of the B-spline bend away from
// the fitted shape (three per pole), within bounds that keep a large face cheap.
int samples_for(int poles) {
  return std::clamp(3 * poles, 9, 60);
}

struct SurfaceSample {
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  // unit; zero where the surface is singular
};

// An n x n grid over the face's parameter bounds, borders included. A first coarse 5 x 5 grid rejects
// free-form faces before the fine one is evaluated.
std::vector<SurfaceSample> sample(const BRepAdaptor_Surface& surface, int nu, int nv) {
  std::vector<SurfaceSample> samples;
  samples.reserve(static_cast<std::size_t>(nu * nv));
  const double u0 = surface.FirstUParameter(), u1 = surface.LastUParameter();
  const double v0 = surface.FirstVParameter(), v1 = surface.LastVParameter();
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      gp_Pnt p;
      gp_Vec du, dv;
      surface.D1(u0 + (u1 - u0) * i / (nu - 1), v0 + (v1 - v0) * j / (nv - 1), p, du, dv);
      const gp_Vec n = du.Crossed(dv);
      samples.push_back(
          {to_eigen(p), n.Magnitude() > 1e-300 ? Eigen::Vector3d(to_eigen(n).normalized()) : Eigen::Vector3d::Zero()});
    }
  }
  return samples;
}

std::pair<int, int> fine_grid(const BRepAdaptor_Surface& surface) {
  return {samples_for(surface.NbUPoles()), samples_for(surface.NbVPoles())};
}

FittedPlane plane_through(const std::vector<SurfaceSample>& samples) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& s : samples) {
    mean += s.point;
  }
  mean /= static_cast<double>(samples.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& s : samples) {
    scatter += (s.point - mean) * (s.point - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  return FittedPlane{mean, eigen.eigenvectors().col(0)};
}

// Every sample within the distance of the plane, and its normal within the angle of the plane's (a
// small curved face can lie within 0.01 mm of a plane and still turn its normal by tenths of a radian).
bool on_plane(const FittedPlane& plane, const std::vector<SurfaceSample>& samples) {
  return std::all_of(samples.begin(), samples.end(), [&](const SurfaceSample& s) {
    return std::abs((s.point - plane.point_m).dot(plane.normal)) <= kTolerance &&
           s.normal.cross(plane.normal).norm() <= kRecognitionTolerance_rad;
  });
}

// The axis is the direction the normals are all perpendicular to (least squares); the circle is fitted
// to the points projected along it (Kasa's algebraic fit, about their mean for conditioning).
std::optional<FittedCylinder> cylinder_through(const std::vector<SurfaceSample>& samples) {
  Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& s : samples) {
    normals += s.normal * s.normal.transpose();
    mean += s.point;
  }
  mean /= static_cast<double>(samples.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(normals);
  if (eigen.eigenvalues()(1) < 1e-12 * static_cast<double>(samples.size())) {
    return std::nullopt;  // the normals are all parallel: a plane, whose "axis" is any direction in it
  }
  const Eigen::Vector3d axis = eigen.eigenvectors().col(0);
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  Eigen::MatrixXd a(static_cast<Eigen::Index>(samples.size()), 3);
  Eigen::VectorXd b(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Eigen::Vector3d d = samples[k].point - mean;
    const double x = d.dot(e1), y = d.dot(e2);
    const auto row = static_cast<Eigen::Index>(k);
    a.row(row) << 2 * x, 2 * y, 1;
    b(row) = x * x + y * y;
  }
  const Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  const double r2 = c(2) + c(0) * c(0) + c(1) * c(1);
  if (!std::isfinite(r2) || r2 <= 0) {
    return std::nullopt;
  }
  return FittedCylinder{mean + c(0) * e1 + c(1) * e2, axis, std::sqrt(r2), 0.0, 0.0, 0.0};
}

bool on_cylinder(const FittedCylinder& cylinder, const std::vector<SurfaceSample>& samples) {
  return std::all_of(samples.begin(), samples.end(), [&](const SurfaceSample& s) {
    const Eigen::Vector3d d = s.point - cylinder.axis_point_m;
    const Eigen::Vector3d radial = d - d.dot(cylinder.axis) * cylinder.axis;
    return std::abs(radial.norm() - cylinder.radius_m) <= kTolerance &&
           s.normal.cross(radial.normalized()).norm() <= kRecognitionTolerance_rad;
  });
}

// The face's angular span and axial extent, from its boundary edges (not its parameter box, which a
// trimmed face need not fill): a face with a seam goes round the full circle; otherwise it spans the
// circle less the largest gap between its boundary points.
bool measure_extent(const BRepAdaptor_Surface& surface, FittedCylinder& cylinder) {
  const Eigen::Vector3d e1 = cylinder.axis.unitOrthogonal(), e2 = cylinder.axis.cross(e1);
  std::vector<double> angles;
  double lo = 1e300, hi = -1e300;
  bool seam = false;
  const TopoDS_Face& face = surface.Face();
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
    seam = seam || BRep_Tool::IsClosed(edge, face);
    if (BRep_Tool::Degenerated(edge)) {
      continue;
    }
    const BRepAdaptor_Curve curve(edge);
    constexpr int kPerEdge = 33;
    for (int k = 0; k < kPerEdge; ++k) {
      const double t = curve.FirstParameter() + (curve.LastParameter() - curve.FirstParameter()) * k / (kPerEdge - 1);
      const Eigen::Vector3d d = to_eigen(curve.Value(t)) - cylinder.axis_point_m;
      const double along = d.dot(cylinder.axis);
      lo = std::min(lo, along);
      hi = std::max(hi, along);
      angles.push_back(std::atan2(d.dot(e2), d.dot(e1)));
    }
  }
  if (angles.empty()) {
    return false;  // no boundary: no extent to measure
  }
  cylinder.axial_min = lo;
  cylinder.axial_max = hi;
  if (seam || angles.size() < 2) {
    cylinder.angle_rad = 2 * kPi;
    return true;
  }
  std::sort(angles.begin(), angles.end());
  double gap = angles.front() + 2 * kPi - angles.back();
  for (std::size_t k = 1; k < angles.size(); ++k) {
    gap = std::max(gap, angles[k] - angles[k - 1]);
  }
  cylinder.angle_rad = 2 * kPi - gap;
  return true;
}

std::vector<Eigen::Vector3d> sample(const BRepAdaptor_Curve& curve, int n) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(n));
  const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
  for (int k = 0; k < n; ++k) {
    points.push_back(to_eigen(curve.Value(t0 + (t1 - t0) * k / (n - 1))));
  }
  return points;
}

int curve_samples(const BRepAdaptor_Curve& curve) {
  return std::clamp(3 * curve.NbPoles(), 9, 120);
}

}  // namespace

std::optional<FittedPlane> fit_plane(const BRepAdaptor_Surface& surface) {
  if (!freeform(surface.GetType())) {
    return std::nullopt;
  }
  const std::vector<SurfaceSample> coarse = sample(surface, 5, 5);
  const FittedPlane plane = plane_through(coarse);
  const auto [nu, nv] = fine_grid(surface);
  if (!on_plane(plane, coarse) || !on_plane(plane, sample(surface, nu, nv))) {
    return std::nullopt;
  }
  return plane;
}

std::optional<FittedCylinder> fit_cylinder(const BRepAdaptor_Surface& surface) {
  if (!freeform(surface.GetType())) {
    return std::nullopt;
  }
  const std::vector<SurfaceSample> coarse = sample(surface, 5, 5);
  if (std::any_of(coarse.begin(), coarse.end(), [](const SurfaceSample& s) { return s.normal.isZero(); })) {
    return std::nullopt;  // a singular point: a cone's apex or a sphere's pole, never on a cylinder
  }
  auto cylinder = cylinder_through(coarse);
  if (!cylinder || !on_cylinder(*cylinder, coarse)) {
    return std::nullopt;
  }
  const auto [nu, nv] = fine_grid(surface);
  const std::vector<SurfaceSample> fine = sample(surface, nu, nv);
  if (!on_cylinder(*cylinder, fine)) {
    return std::nullopt;
  }
  // Refined on every sample, and checked again against the refined fit.
  cylinder = cylinder_through(fine);
  if (!cylinder || !on_cylinder(*cylinder, fine)) {
    return std::nullopt;
  }
  if (!measure_extent(surface, *cylinder)) {
    return std::nullopt;
  }
  return cylinder;
}

std::optional<FittedLine> fit_line(const BRepAdaptor_Curve& curve) {
  if (!freeform(curve.GetType())) {
    return std::nullopt;
  }
  const std::vector<Eigen::Vector3d> points = sample(curve, curve_samples(curve));
  const Eigen::Vector3d chord = points.back() - points.front();
  if (chord.norm() <= kTolerance) {
    return std::nullopt;
  }
  const Eigen::Vector3d direction = chord.normalized();
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - points.front();
    if ((d - d.dot(direction) * direction).norm() > kTolerance) {
      return std::nullopt;
    }
  }
  return FittedLine{direction};
}

std::optional<FittedCircle> fit_circle(const BRepAdaptor_Curve& curve) {
  if (!freeform(curve.GetType())) {
    return std::nullopt;
  }
  const int n = curve_samples(curve);
  const std::vector<Eigen::Vector3d> points = sample(curve, n);
  // The circle through three points spread over the edge (a closed edge's ends coincide: use thirds).
  const Eigen::Vector3d& a = points.front();
  const Eigen::Vector3d& b = points[static_cast<std::size_t>(n / 3)];
  const Eigen::Vector3d& c = points[static_cast<std::size_t>(2 * n / 3)];
  const Eigen::Vector3d ab = b - a, ac = c - a;
  const Eigen::Vector3d normal = ab.cross(ac);
  if (normal.norm() <= kTolerance * std::max(ab.norm(), ac.norm())) {
    return std::nullopt;  // (nearly) collinear: a line, or too flat an arc to tell
  }
  const Eigen::Vector3d centre =
      a + (ac.squaredNorm() * normal.cross(ab) + ab.squaredNorm() * ac.cross(normal)) / (2 * normal.squaredNorm());
  const Eigen::Vector3d axis = normal.normalized();
  const double radius = (a - centre).norm();
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - centre;
    if (std::abs(d.dot(axis)) > kTolerance || std::abs(d.norm() - radius) > kTolerance) {
      return std::nullopt;
    }
  }
  return FittedCircle{centre, axis, radius};
}

std::optional<bool> outside_along(const TopoDS_Shape& solid, const Eigen::Vector3d& point_m,
                                  const Eigen::Vector3d& direction) {
  IntCurvesFace_ShapeIntersector intersector;
  intersector.Load(solid, 1e-7);
  intersector.PerformNearest(gp_Lin(to_gp_pnt(point_m), gp_Dir(direction.x(), direction.y(), direction.z())), 1e-7,
                             Precision::Infinite());
  if (!intersector.IsDone()) {
    return std::nullopt;
  }
  if (intersector.NbPnt() == 0) {
    return true;
  }
  if (intersector.State(1) != TopAbs_IN) {
    return std::nullopt;  // on an edge or a vertex: the crossing's side is not the face's alone
  }
  const TopoDS_Face& face = intersector.Face(1);
  const BRepAdaptor_Surface surface(face, false);
  gp_Pnt p;
  gp_Vec du, dv;
  surface.D1(intersector.UParameter(1), intersector.VParameter(1), p, du, dv);
  gp_Vec normal = du.Crossed(dv);
  if (normal.Magnitude() < 1e-300) {
    return std::nullopt;
  }
  if (face.Orientation() == TopAbs_REVERSED) {
    normal.Reverse();
  }
  const double along = to_eigen(normal.Normalized()).dot(direction);
  if (std::abs(along) < 1e-6) {
    return std::nullopt;  // tangent
  }
  return along < 0;  // the ray enters the material first: the point is outside
}

}  // namespace rigger::cad::detail
