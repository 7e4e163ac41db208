#include "rigger/cad/features.hpp"

#include "occt_util.hpp"
#include "recognise.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <OSD_Parallel.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <gp_Circ.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Lin.hxx>
#include <gp_Pln.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>
#include <optional>

namespace rigger::cad {

std::string_view to_string(EntityKind kind) {
  switch (kind) {
    case EntityKind::kFace: return "face";
    case EntityKind::kEdge: return "edge";
    case EntityKind::kVertex: return "vertex";
  }
  return "entity";
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// Axes and line directions have no sign of their own: make the first clearly non-zero component positive
// so that the same geometry always gets the same signature.
Eigen::Vector3d canonical(Eigen::Vector3d direction) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(direction[i]) > 1e-9) {
      return direction[i] < 0 ? Eigen::Vector3d(-direction) : direction;
    }
  }
  return direction;
}

std::string surface_type(GeomAbs_SurfaceType type) {
  switch (type) {
    case GeomAbs_Plane: return "plane";
    case GeomAbs_Cylinder: return "cylinder";
    case GeomAbs_Cone: return "cone";
    case GeomAbs_Sphere: return "sphere";
    case GeomAbs_Torus: return "torus";
    case GeomAbs_BSplineSurface:
    case GeomAbs_BezierSurface: return "bspline";
    default: return "other";
  }
}

// The outward normal of `face` at its parametric middle (face orientation applied).
Eigen::Vector3d outward_normal(const TopoDS_Face& face, const BRepAdaptor_Surface& surface, Eigen::Vector3d* point) {
  const double u = 0.5 * (surface.FirstUParameter() + surface.LastUParameter());
  const double v = 0.5 * (surface.FirstVParameter() + surface.LastVParameter());
  gp_Pnt p;
  gp_Vec du, dv;
  surface.D1(u, v, p, du, dv);
  gp_Vec n = du.Crossed(dv);
  if (face.Orientation() == TopAbs_REVERSED) {
    n.Reverse();
  }
  if (point != nullptr) {
    *point = to_eigen(p);
  }
  return n.Magnitude() > 0 ? Eigen::Vector3d(to_eigen(n).normalized()) : Eigen::Vector3d::Zero();
}

// Relative error bound on the area of a face that is not an elementary surface (B-spline, Bezier,
// revolution, extrusion, offset), integrated adaptively.
constexpr double kFreeformAreaTolerance = 1e-3;
constexpr double kRecognisedAreaTolerance = 1e-6;

bool elementary(GeomAbs_SurfaceType type) {
  return type == GeomAbs_Plane || type == GeomAbs_Cylinder || type == GeomAbs_Cone || type == GeomAbs_Sphere ||
         type == GeomAbs_Torus;
}

// The cylinder of an analytic face in the terms of a fitted one: its V parameter is the distance along
// the axis from the cylinder's location, its U parameter the angle.
detail::FittedCylinder analytic_cylinder(const BRepAdaptor_Surface& surface) {
  const gp_Cylinder cylinder = surface.Cylinder();
  return {to_eigen(cylinder.Location()),
          to_eigen(cylinder.Axis().Direction()),
          cylinder.Radius(),
          surface.LastUParameter() - surface.FirstUParameter(),
          surface.FirstVParameter(),
          surface.LastVParameter()};
}

FaceInfo face_info(const TopoDS_Face& face, int index) {
  FaceInfo info;
  info.index = index;
  const BRepAdaptor_Surface surface(face);
  // A B-spline or Bezier face that is a plane or a cylinder within 0.01 mm is classified as one: many
  // exporters write every surface as a B-spline, and its holes and planar faces are still holes and faces.
  GeomAbs_SurfaceType type = surface.GetType();
  std::optional<detail::FittedCylinder> cylinder;
  if (detail::fit_plane(surface)) {
    type = GeomAbs_Plane;
    info.recognised = true;
  } else if ((cylinder = detail::fit_cylinder(surface))) {
    type = GeomAbs_Cylinder;
    info.recognised = true;
  }
  GProp_GProps props;
  if (info.recognised) {
    BRepGProp::SurfaceProperties(face, props, kRecognisedAreaTolerance);
  } else if (elementary(surface.GetType())) {
    // OCCT's fixed-order Gauss integration: cheap on these surfaces (the shipped cell's references were
    // taken with it, and keep matching to the last bit).
    BRepGProp::SurfaceProperties(face, props);
  } else {
    // On B-spline faces the fixed-order integration evaluates the surface at (knot spans x order)^2 points
    // per boundary span and took most of classify(); the adaptive one with a 1e-3 relative area bound is
    // 4-5x cheaper and agrees with it on linkrods.step within 1e-7 m (neither is exact: they differ from a
    // 1e-10 adaptive integral by up to 2e-4 and 7e-5 of the face's size). Deterministic like the other.
    BRepGProp::SurfaceProperties(face, props, kFreeformAreaTolerance);
  }
  info.area_m2 = props.Mass();
  info.signature.centroid_m = to_eigen(props.CentreOfMass());
  info.signature.type = surface_type(type);
  switch (type) {
    case GeomAbs_Plane:
      info.normal = outward_normal(face, surface, nullptr);
      info.signature.direction = info.normal;
      break;
    case GeomAbs_Cylinder: {
      const detail::FittedCylinder c = cylinder ? *cylinder : analytic_cylinder(surface);
      const Eigen::Vector3d& axis = c.axis;
      const Eigen::Vector3d& origin = c.axis_point_m;
      info.signature.direction = canonical(axis);
      info.signature.radius_m = c.radius_m;
      Eigen::Vector3d point;
      const Eigen::Vector3d normal = outward_normal(face, surface, &point);
      const Eigen::Vector3d radial = (point - origin) - (point - origin).dot(axis) * axis;
      info.material_outside = normal.dot(radial) < 0;
      info.angle_rad = c.angle_rad;
      // Extent along the canonical axis, measured from the foot of the origin.
      const double sign = axis.dot(info.signature.direction);
      const double a = sign * c.axial_min, b = sign * c.axial_max;
      info.axis_point_m = origin;
      info.axial_min = std::min(a, b);
      info.axial_max = std::max(a, b);
      break;
    }
    case GeomAbs_Cone:
      info.signature.direction = canonical(to_eigen(surface.Cone().Axis().Direction()));
      break;
    case GeomAbs_Sphere:
      info.signature.radius_m = surface.Sphere().Radius();
      break;
    case GeomAbs_Torus:
      info.signature.direction = canonical(to_eigen(surface.Torus().Axis().Direction()));
      info.signature.radius_m = surface.Torus().MajorRadius();
      break;
    default: break;
  }
  return info;
}

EdgeInfo edge_info(const TopoDS_Edge& edge, int index) {
  EdgeInfo info;
  info.index = index;
  TopoDS_Vertex first, last;
  TopExp::Vertices(edge, first, last, true);
  if (!first.IsNull()) {
    info.start_m = to_eigen(BRep_Tool::Pnt(first));
  }
  if (!last.IsNull()) {
    info.end_m = to_eigen(BRep_Tool::Pnt(last));
  }
  if (BRep_Tool::Degenerated(edge)) {
    info.signature.type = "degenerate";
    info.signature.centroid_m = info.start_m;
    return info;
  }
  GProp_GProps props;
  BRepGProp::LinearProperties(edge, props);
  info.length_m = props.Mass();
  info.signature.centroid_m = to_eigen(props.CentreOfMass());
  const BRepAdaptor_Curve curve(edge);
  switch (curve.GetType()) {
    case GeomAbs_Line:
      info.signature.type = "line";
      info.signature.direction = canonical(to_eigen(curve.Line().Direction()));
      break;
    case GeomAbs_Circle:
      info.signature.type = "circle";
      info.signature.direction = canonical(to_eigen(curve.Circle().Axis().Direction()));
      info.signature.radius_m = curve.Circle().Radius();
      // A circle's centroid is off its centre when it is an arc; the signature keeps the centre.
      info.signature.centroid_m = to_eigen(curve.Circle().Location());
      break;
    default:
      // A B-spline or Bezier edge that is a line or a circle within 0.01 mm, as for faces.
      if (const auto line = detail::fit_line(curve)) {
        info.signature.type = "line";
        info.signature.direction = canonical(line->direction);
        info.recognised = true;
      } else if (const auto circle = detail::fit_circle(curve)) {
        info.signature.type = "circle";
        info.signature.direction = canonical(circle->axis);
        info.signature.radius_m = circle->radius_m;
        info.signature.centroid_m = circle->centre_m;
        info.recognised = true;
      } else {
        info.signature.type = "other";
      }
      break;
  }
  return info;
}

bool coaxial(const FaceInfo& a, const FaceInfo& b, double tolerance_m, double tolerance_rad) {
  if (std::abs(a.signature.radius_m - b.signature.radius_m) > tolerance_m) {
    return false;
  }
  if (a.signature.direction.cross(b.signature.direction).norm() > tolerance_rad) {
    return false;
  }
  const Eigen::Vector3d& axis = a.signature.direction;
  const Eigen::Vector3d offset = b.axis_point_m - a.axis_point_m;
  return (offset - offset.dot(axis) * axis).norm() <= tolerance_m;
}

}  // namespace

bool same_signature(const Signature& a, const Signature& b, double tolerance_m, double tolerance_rad) {
  return a.type == b.type && (a.centroid_m - b.centroid_m).norm() <= tolerance_m &&
         (a.direction - b.direction).norm() <= tolerance_rad && std::abs(a.radius_m - b.radius_m) <= tolerance_m;
}

int Features::count_faces(const std::string& type) const {
  return static_cast<int>(std::count_if(faces.begin(), faces.end(), [&](const FaceInfo& f) { return f.signature.type == type; }));
}

int Features::count_edges(const std::string& type) const {
  return static_cast<int>(std::count_if(edges.begin(), edges.end(), [&](const EdgeInfo& e) { return e.signature.type == type; }));
}

const Signature& Features::signature(EntityKind kind, int index) const {
  const auto check = [&](std::size_t size) {
    if (index < 0 || static_cast<std::size_t>(index) >= size) {
      throw CadError(ErrorCode::kBadReference, "model " + model_sha256.substr(0, 12) + " has no " +
                                                   std::string(to_string(kind)) + " " + std::to_string(index) + " (it has " +
                                                   std::to_string(size) + ", numbered from 0)");
    }
  };
  static thread_local Signature vertex_signature;
  switch (kind) {
    case EntityKind::kFace: check(faces.size()); return faces[static_cast<std::size_t>(index)].signature;
    case EntityKind::kEdge: check(edges.size()); return edges[static_cast<std::size_t>(index)].signature;
    case EntityKind::kVertex:
      check(vertices.size());
      vertex_signature = Signature{"vertex", vertices[static_cast<std::size_t>(index)].point_m, Eigen::Vector3d::Zero(), 0.0};
      return vertex_signature;
  }
  throw CadError(ErrorCode::kBadReference, "unknown entity kind");
}

Reference Features::reference(EntityKind kind, int index) const {
  return Reference{model_sha256, kind, index, signature(kind, index)};
}

Features classify(const Model& model) {
  Features features;
  features.model_sha256 = model.sha256();
  const TopoDS_Shape& shape = model.shape();
  TopTools_IndexedMapOfShape faces, edges, vertices, solids;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  features.solids = solids.Extent();
  TopTools_IndexedDataMapOfShapeListOfShape face_solids;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_FACE, TopAbs_SOLID, face_solids);

  // Faces and edges are measured independently of each other (the integrals of B-spline faces are most
  // of the time): in parallel, each into its own slot. OCCT's evaluators are per call, the B-rep is
  // only read.
  features.faces.resize(static_cast<std::size_t>(faces.Extent()));
  features.edges.resize(static_cast<std::size_t>(edges.Extent()));
  OSD_Parallel::For(0, faces.Extent() + edges.Extent(), [&](int k) {
    if (k < faces.Extent()) {
      features.faces[static_cast<std::size_t>(k)] = face_info(TopoDS::Face(faces(k + 1)), k);
    } else {
      const int e = k - faces.Extent();
      features.edges[static_cast<std::size_t>(e)] = edge_info(TopoDS::Edge(edges(e + 1)), e);
    }
  });
  for (int i = 1; i <= faces.Extent(); ++i) {
    const int at = face_solids.FindIndex(faces(i));
    if (at > 0 && !face_solids(at).IsEmpty()) {
      features.faces[static_cast<std::size_t>(i - 1)].solid = solids.FindIndex(face_solids(at).First()) - 1;
    }
  }
  features.vertices.reserve(static_cast<std::size_t>(vertices.Extent()));
  for (int i = 1; i <= vertices.Extent(); ++i) {
    features.vertices.push_back(VertexInfo{i - 1, to_eigen(BRep_Tool::Pnt(TopoDS::Vertex(vertices(i))))});
  }

  // Whether a point is outside solid `s`. A point outside the solid's bounding box (from the geometry,
  // not a triangulation, so that the answer does not depend on meshing) is outside: the probes beyond a
  // hole's ends usually are, and building OCCT's classifier of a B-spline solid costs tens of ms. For a
  // hole recognised from B-spline faces, the first face crossed going `away` along the axis (the classifier
  // took about 1.5 s per point on such a solid). Else one classifier per solid, built when first needed.
  std::vector<std::optional<Bnd_Box>> solid_boxes(static_cast<std::size_t>(solids.Extent()));
  std::vector<std::unique_ptr<BRepClass3d_SolidClassifier>> classifiers(static_cast<std::size_t>(solids.Extent()));
  const auto outside = [&](int s, const Eigen::Vector3d& point, const Eigen::Vector3d& away, bool bspline) {
    const auto at = static_cast<std::size_t>(s);
    if (!solid_boxes[at]) {
      solid_boxes[at].emplace();
      BRepBndLib::Add(solids(s + 1), *solid_boxes[at], false);
      solid_boxes[at]->Enlarge(1e-7);  // the classifier's tolerance below
    }
    if (solid_boxes[at]->IsOut(to_gp_pnt(point))) {
      return true;
    }
    if (bspline) {
      if (const auto answer = detail::outside_along(solids(s + 1), point, away)) {
        return *answer;
      }
    }
    if (!classifiers[at]) {
      classifiers[at] = std::make_unique<BRepClass3d_SolidClassifier>(solids(s + 1));
    }
    classifiers[at]->Perform(to_gp_pnt(point), 1e-7);
    return classifiers[at]->State() == TopAbs_OUT;
  };

  // Holes: concave cylinders grouped by axis, radius, solid and touching axial extents.
  constexpr double kTolerance = 1e-7;
  std::vector<std::vector<int>> groups;
  for (const auto& face : features.faces) {
    if (face.signature.type != "cylinder" || !face.material_outside) {
      continue;
    }
    bool placed = false;
    for (auto& group : groups) {
      const FaceInfo& other = features.faces[static_cast<std::size_t>(group.front())];
      if (other.solid != face.solid || !coaxial(other, face, kTolerance * 10, 1e-7)) {
        continue;
      }
      const Eigen::Vector3d& axis = other.signature.direction;
      const double shift = (face.axis_point_m - other.axis_point_m).dot(axis);
      double lo = 1e300, hi = -1e300;
      for (int member : group) {
        const FaceInfo& m = features.faces[static_cast<std::size_t>(member)];
        const double s = (m.axis_point_m - other.axis_point_m).dot(axis);
        lo = std::min(lo, m.axial_min + s);
        hi = std::max(hi, m.axial_max + s);
      }
      if (face.axial_min + shift <= hi + 1e-6 && face.axial_max + shift >= lo - 1e-6) {
        group.push_back(face.index);
        placed = true;
        break;
      }
    }
    if (!placed) {
      groups.push_back({face.index});
    }
  }
  for (const auto& group : groups) {
    const FaceInfo& first = features.faces[static_cast<std::size_t>(group.front())];
    double angle = 0, lo = 1e300, hi = -1e300;
    for (int member : group) {
      const FaceInfo& m = features.faces[static_cast<std::size_t>(member)];
      const double s = (m.axis_point_m - first.axis_point_m).dot(first.signature.direction);
      angle += m.angle_rad;
      lo = std::min(lo, m.axial_min + s);
      hi = std::max(hi, m.axial_max + s);
    }
    if (angle < 2 * kPi - 1e-6) {
      continue;  // a concave fillet or a slot end, not a hole
    }
    const Eigen::Vector3d axis = first.signature.direction;
    const Eigen::Vector3d end_lo = first.axis_point_m + lo * axis;
    const Eigen::Vector3d end_hi = first.axis_point_m + hi * axis;
    const double radius = first.signature.radius_m;
    // An end is open when a point on the axis a little beyond it (3/4 of the radius: past the tip of a
    // 118° drill point) is outside the material of the hole's solid.
    bool open_lo = true, open_hi = true;
    if (first.solid >= 0) {
      const double probe = 0.75 * radius;
      open_lo = outside(first.solid, end_lo - probe * axis, -axis, first.recognised);
      open_hi = outside(first.solid, end_hi + probe * axis, axis, first.recognised);
    }
    Hole hole;
    hole.index = static_cast<int>(features.holes.size());
    hole.faces = group;
    std::sort(hole.faces.begin(), hole.faces.end());
    hole.diameter_m = 2 * radius;
    hole.depth_m = hi - lo;
    hole.through = open_lo && open_hi;
    bool entry_hi = open_hi && !open_lo;
    if (open_lo == open_hi) {
      // Through (or closed): the end whose outward axis points most up (z, then y, then x).
      entry_hi = true;
      for (int i = 2; i >= 0; --i) {
        if (std::abs(axis[i]) > 1e-9) {
          entry_hi = axis[i] > 0;
          break;
        }
      }
    }
    hole.axis = entry_hi ? axis : Eigen::Vector3d(-axis);
    hole.entry_m = entry_hi ? end_hi : end_lo;
    features.holes.push_back(std::move(hole));
  }
  return features;
}

int resolve(const Features& features, const Reference& ref, double tolerance_m, double tolerance_rad) {
  const std::size_t count = ref.kind == EntityKind::kFace   ? features.faces.size()
                            : ref.kind == EntityKind::kEdge ? features.edges.size()
                                                            : features.vertices.size();
  if (ref.index >= 0 && static_cast<std::size_t>(ref.index) < count &&
      same_signature(features.signature(ref.kind, ref.index), ref.signature, tolerance_m, tolerance_rad)) {
    return ref.index;
  }
  int found = -1, matches = 0;
  for (std::size_t i = 0; i < count; ++i) {
    if (same_signature(features.signature(ref.kind, static_cast<int>(i)), ref.signature, tolerance_m, tolerance_rad)) {
      found = static_cast<int>(i);
      ++matches;
    }
  }
  if (matches == 1) {
    return found;
  }
  const auto mm = [](const Eigen::Vector3d& p) {
    char text[96];
    std::snprintf(text, sizeof text, "[%.1f, %.1f, %.1f] mm", p.x() * 1e3, p.y() * 1e3, p.z() * 1e3);
    return std::string(text);
  };
  std::string why = std::string(to_string(ref.kind)) + " " + std::to_string(ref.index) + " (" + ref.signature.type +
                    " at " + mm(ref.signature.centroid_m) + ") of model " + ref.model_sha256.substr(0, 12);
  if (ref.index >= 0 && static_cast<std::size_t>(ref.index) < count) {
    const Signature& now = features.signature(ref.kind, ref.index);
    why += " is now a " + now.type + " at " + mm(now.centroid_m);
  } else {
    why += " no longer exists";
  }
  why += matches == 0 ? " and no entity of model " + features.model_sha256.substr(0, 12) + " has its signature"
                      : " and " + std::to_string(matches) + " entities have its signature";
  throw StaleReference(why);
}

}  // namespace rigger::cad
