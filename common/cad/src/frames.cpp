#include "rigger/cad/frames.hpp"

#include "occt_util.hpp"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <GeomLProp_SLProps.hxx>
#include <Geom_Surface.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <gp_Pnt2d.hxx>

#include <cmath>
#include <sstream>

namespace rigger::cad {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string text(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}

const EdgeInfo& line_edge(const Features& features, int index) {
  features.signature(EntityKind::kEdge, index);  // throws kBadReference when out of range
  const EdgeInfo& edge = features.edges[static_cast<std::size_t>(index)];
  if (edge.signature.type != "line") {
    throw CadError(ErrorCode::kNotAFrame,
                   "edge " + std::to_string(index) + " is a " + edge.signature.type + ", not a straight line: it gives no direction");
  }
  return edge;
}

}  // namespace

Eigen::Matrix3d rotation_from_z(const Eigen::Vector3d& z_in, const Eigen::Vector3d& x_hint) {
  const Eigen::Vector3d z = z_in.normalized();
  Eigen::Vector3d x = x_hint - x_hint.dot(z) * z;
  if (x.norm() < 1e-6) {
    x = Eigen::Vector3d::UnitY() - z.y() * z;
  }
  x.normalize();
  Eigen::Matrix3d rotation;
  rotation.col(0) = x;
  rotation.col(1) = z.cross(x);
  rotation.col(2) = z;
  return rotation;
}

Eigen::Isometry3d frame_from_edges(const Features& features, const Eigen::Vector3d& point_m, int edge_x, int edge_y,
                                   const FrameTolerances& tolerances) {
  if (edge_x == edge_y) {
    throw CadError(ErrorCode::kNotAFrame, "the two edges are the same edge " + std::to_string(edge_x));
  }
  const EdgeInfo& a = line_edge(features, edge_x);
  const EdgeInfo& b = line_edge(features, edge_y);
  const Eigen::Vector3d x = (a.end_m - a.start_m).normalized();
  const Eigen::Vector3d y_raw = (b.end_m - b.start_m).normalized();
  const double angle = std::acos(std::clamp(x.dot(y_raw), -1.0, 1.0));
  if (std::abs(angle - kPi / 2) > tolerances.perpendicular_rad) {
    throw CadError(ErrorCode::kNotAFrame, "edges " + std::to_string(edge_x) + " and " + std::to_string(edge_y) +
                                              " make " + text(angle * 180 / kPi) + "°, not 90° within " +
                                              text(tolerances.perpendicular_rad * 180 / kPi) + "°");
  }
  const Eigen::Vector3d y = (y_raw - y_raw.dot(x) * x).normalized();
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear().col(0) = x;
  frame.linear().col(1) = y;
  frame.linear().col(2) = x.cross(y);
  frame.translation() = point_m;
  return frame;
}

Eigen::Isometry3d frame_from_face(const Model& model, const Features& features, int face_index,
                                  const Eigen::Vector3d& point_m, const FrameTolerances& tolerances) {
  features.signature(EntityKind::kFace, face_index);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(model.shape(), TopAbs_FACE, faces);
  if (faces.Extent() != static_cast<int>(features.faces.size())) {
    throw CadError(ErrorCode::kBadReference, "the features were not classified from this model");
  }
  const TopoDS_Face face = TopoDS::Face(faces(face_index + 1));
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  GeomAPI_ProjectPointOnSurf projection(to_gp_pnt(point_m), surface);
  if (projection.NbPoints() == 0) {
    throw CadError(ErrorCode::kNotAFrame, "the point cannot be projected onto face " + std::to_string(face_index));
  }
  const double distance = projection.LowerDistance();
  if (distance > tolerances.on_face_m) {
    throw CadError(ErrorCode::kNotAFrame, "the point is " + text(distance * 1000) + " mm from the surface of face " +
                                              std::to_string(face_index) + " (at most " +
                                              text(tolerances.on_face_m * 1000) + " mm): it is not on the face");
  }
  double u = 0, v = 0;
  projection.LowerDistanceParameters(u, v);
  BRepClass_FaceClassifier inside(face, gp_Pnt2d(u, v), tolerances.on_face_m);
  if (inside.State() == TopAbs_OUT) {
    throw CadError(ErrorCode::kNotAFrame,
                   "the point lies on the surface of face " + std::to_string(face_index) + " but outside its boundary");
  }
  GeomLProp_SLProps props(surface, u, v, 1, 1e-9);
  if (!props.IsNormalDefined()) {
    throw CadError(ErrorCode::kNotAFrame, "face " + std::to_string(face_index) + " has no normal at the point (a singularity)");
  }
  Eigen::Vector3d normal = to_eigen(props.Normal());
  if (face.Orientation() == TopAbs_REVERSED) {
    normal = -normal;
  }
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = rotation_from_z(normal);
  frame.translation() = to_eigen(projection.NearestPoint());
  return frame;
}

Eigen::Isometry3d frame_from_hole(const Features& features, int hole) {
  if (hole < 0 || static_cast<std::size_t>(hole) >= features.holes.size()) {
    throw CadError(ErrorCode::kBadReference, "model " + features.model_sha256.substr(0, 12) + " has no hole " +
                                                 std::to_string(hole) + " (it has " +
                                                 std::to_string(features.holes.size()) + ", numbered from 0)");
  }
  const Hole& h = features.holes[static_cast<std::size_t>(hole)];
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = rotation_from_z(h.axis);
  frame.translation() = h.entry_m;
  return frame;
}

Eigen::Isometry3d frame_above_centre_of_mass(const Model& model, double clearance_m) {
  GProp_GProps properties;
  BRepGProp::VolumeProperties(model.shape(), properties);
  if (!(properties.Mass() > 1e-12)) {
    throw CadError(ErrorCode::kNotAFrame, "model " + model.sha256().substr(0, 12) +
                                              " has no volume (no solid): its centre of mass is unknown");
  }
  Bnd_Box bounds;
  BRepBndLib::AddOptimal(model.shape(), bounds, false, false);
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  bounds.Get(x0, y0, z0, x1, y1, z1);
  const gp_Pnt centre = properties.CentreOfMass();
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.translation() = Eigen::Vector3d(centre.X(), centre.Y(), z1 + clearance_m);
  return frame;
}

}  // namespace rigger::cad
