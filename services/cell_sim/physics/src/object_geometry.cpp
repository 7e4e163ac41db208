// The cell file's objects as the physics builds them: the box shorthand or the STEP model's solids,
// tessellated for MuJoCo's convex mesh geoms, and the mass.
#include "object_geometry.hpp"

#include <BRepGProp.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>

#include <algorithm>
#include <limits>
#include <set>
#include <tuple>

#include "rigger/cad/model.hpp"

namespace rigger::sim::detail {
namespace {

// Tessellation tolerance for the collision hulls: a hull only needs the extreme points, so a coarse mesh
// (0.5 mm, 0.5 rad) is exact on planar solids and within 0.5 mm on curved ones.
constexpr double kLinearDeflectionM = 0.0005;
constexpr double kAngularDeflectionRad = 0.5;

// The distinct tessellation nodes of a solid's faces (after BRepMesh), in the model's frame.
std::vector<Eigen::Vector3d> solid_vertices(const TopoDS_Solid& solid) {
  std::set<std::tuple<double, double, double>> seen;
  std::vector<Eigen::Vector3d> vertices;
  for (TopExp_Explorer faces(solid, TopAbs_FACE); faces.More(); faces.Next()) {
    TopLoc_Location location;
    const Handle(Poly_Triangulation) mesh = BRep_Tool::Triangulation(TopoDS::Face(faces.Current()), location);
    if (mesh.IsNull()) continue;
    for (int i = 1; i <= mesh->NbNodes(); ++i) {
      const gp_Pnt point = mesh->Node(i).Transformed(location);
      if (seen.emplace(point.X(), point.Y(), point.Z()).second) vertices.emplace_back(point.X(), point.Y(), point.Z());
    }
  }
  return vertices;
}

struct StepGeometry {
  std::vector<ObjectSolid> solids;
  double volume_m3 = 0.0;
};

StepGeometry read_step_solids(const cell::CellFile& file, const cell::CellEntity& entity,
                              const std::filesystem::path& model_dir,
                              const std::map<std::string, cad::Model>& read_models) {
  const std::string pointer = entity.pointer + "/model/step";
  const std::string expected = "a STEP model of closed solids";
  const std::filesystem::path path = model_dir / entity.model->step;
  StepGeometry geometry;
  try {
    const auto known = read_models.find(entity.id);
    const cad::Model model = known != read_models.end() ? known->second : cad::read_step_file(path);
    if (const std::string stale = cell::stale_model_problem(*entity.model, model.sha256()); !stale.empty())
      file.fail(entity.pointer + "/model/sha256", "the pinned bytes of " + path.string(), stale);
    if (const std::string problem = cad::solid_problem(model); !problem.empty())
      file.fail(pointer, expected, path.string() + ": " + problem);
    BRepMesh_IncrementalMesh mesher(model.shape(), kLinearDeflectionM, false, kAngularDeflectionRad, true);
    int index = 0;
    for (TopExp_Explorer solids(model.shape(), TopAbs_SOLID); solids.More(); solids.Next(), ++index) {
      const TopoDS_Solid& solid = TopoDS::Solid(solids.Current());
      const std::string which = path.string() + ": solid " + std::to_string(index);
      GProp_GProps properties;
      BRepGProp::VolumeProperties(solid, properties);
      ObjectSolid object_solid{solid_vertices(solid), properties.Mass()};
      if (!(object_solid.volume_m3 > 0.0)) file.fail(pointer, expected, which + " has no volume");
      if (object_solid.vertices_m.size() < 4) file.fail(pointer, expected, which + " did not tessellate");
      geometry.volume_m3 += object_solid.volume_m3;
      geometry.solids.push_back(std::move(object_solid));
    }
  } catch (const cad::CadError& error) {
    file.fail(pointer, expected, error.what());
  } catch (const Standard_Failure& failure) {
    file.fail(pointer, expected, path.string() + ": OpenCascade: " + failure.GetMessageString());
  }
  return geometry;
}

}  // namespace

std::pair<Eigen::Vector3d, Eigen::Vector3d> vertex_bounds(const std::vector<ObjectSolid>& solids) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const ObjectSolid& solid : solids) {
    for (const Eigen::Vector3d& vertex : solid.vertices_m) {
      low = low.cwiseMin(vertex);
      high = high.cwiseMax(vertex);
    }
  }
  return {0.5 * (low + high), high - low};
}

ObjectGeometry object_geometry_from(const cell::CellFile& file, const cell::CellEntity& entity,
                                    const std::filesystem::path& model_dir,
                                    const std::map<std::string, cad::Model>& read_models) {
  if (!entity.model) {
    file.fail(entity.pointer + "/model", "the geometry of object \"" + entity.id + "\"", "nothing (missing key)");
  }
  const cell::ObjectModel& model = *entity.model;
  ObjectGeometry object;
  object.id = entity.id;
  object.pointer = entity.pointer;
  object.pose_world_object = file.pose_root_entity(entity.id);
  object.is_static = model.is_static;
  object.pose_object_rope_attachment = entity.features.rope_attachment;

  // The STEP model is read for the geometry (no box) or for the volume a density weighs.
  const bool box = model.shape == "box";
  StepGeometry step;
  if (!model.step.empty() && (!box || model.density_kg_m3)) step = read_step_solids(file, entity, model_dir, read_models);
  if (box) {
    object.box_size_m = model.size_m;
    object.box_centre_m = cell::box_centre_in_object_frame(file, entity);
  } else {
    object.solids = std::move(step.solids);
  }

  if (model.mass_kg) {
    object.mass_kg = *model.mass_kg;
  } else if (model.density_kg_m3) {
    object.mass_kg = *model.density_kg_m3 * step.volume_m3;
  } else if (!object.is_static) {
    file.fail(entity.pointer + "/model/mass_kg",
              "the mass of a free object: mass_kg > 0, or density_kg_m3 > 0 with a STEP model (or \"static\": true)",
              "nothing (missing key)");
  }
  return object;
}

}  // namespace rigger::sim::detail

namespace rigger::sim {

std::pair<Eigen::Vector3d, Eigen::Vector3d> ObjectGeometry::bounds_m() const {
  if (box_size_m) return {box_centre_m, *box_size_m};
  return detail::vertex_bounds(solids);
}

}  // namespace rigger::sim
