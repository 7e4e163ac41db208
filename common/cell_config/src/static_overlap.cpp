#include "static_overlap.hpp"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>

#include <cmath>
#include <string>
#include <vector>

namespace rigger::cell::detail {
namespace {

struct PlacedSolid {
  const CellEntity* entity = nullptr;
  bool step = false;
  TopoDS_Shape shape;  // in the root frame, metres
  Bnd_Box bounds;
};

gp_Trsf to_trsf(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Eigen::Vector3d& t = pose.translation();
  gp_Trsf trsf;
  trsf.SetValues(r(0, 0), r(0, 1), r(0, 2), t.x(), r(1, 0), r(1, 1), r(1, 2), t.y(), r(2, 0), r(2, 1), r(2, 2), t.z());
  return trsf;
}

gp_Pnt point(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

}  // namespace

void check_static_solids_apart(const CellFile& file,
                               const std::function<const cad::Model&(const CellEntity&)>& model_of) {
  std::vector<PlacedSolid> solids;
  bool any_step = false;
  for (const CellEntity& entity : file.entities) {
    if (!entity.model || !entity.model->is_static) continue;
    PlacedSolid placed;
    placed.entity = &entity;
    TopoDS_Shape local;
    if (entity.model->shape == "box") {
      const Eigen::Vector3d centre = box_centre_in_object_frame(file, entity);
      const Eigen::Vector3d half = 0.5 * entity.model->size_m;
      local = BRepPrimAPI_MakeBox(point(centre - half), point(centre + half)).Shape();
    } else if (!entity.model->step.empty()) {
      local = model_of(entity).shape();
      placed.step = true;
      any_step = true;
    } else {
      continue;
    }
    placed.shape = BRepBuilderAPI_Transform(local, to_trsf(file.pose_root_entity(entity.id)), true).Shape();
    BRepBndLib::AddOptimal(placed.shape, placed.bounds, false, false);
    solids.push_back(std::move(placed));
  }
  if (!any_step) return;
  for (std::size_t j = 1; j < solids.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const PlacedSolid& a = solids[i];
      const PlacedSolid& b = solids[j];
      if (!a.step && !b.step) continue;        // boxes: load_cell_file's exact check
      if (a.bounds.IsOut(b.bounds)) continue;  // apart at a glance
      BRepAlgoAPI_Common common(a.shape, b.shape);
      if (!common.IsDone()) {
        file.fail(b.entity->pointer + "/pose", "static objects apart (they may touch, not overlap)",
                  "OpenCascade could not intersect its solid with static object \"" + a.entity->id + "\" (" +
                      a.entity->pointer + ")");
      }
      GProp_GProps props;
      BRepGProp::VolumeProperties(common.Shape(), props);
      const double shared_m3 = std::abs(props.Mass());
      if (shared_m3 > kMaxSharedVolume_m3) {
        file.fail(b.entity->pointer + "/pose", "static objects apart (they may touch, not overlap)",
                  "its solid shares " + std::to_string(static_cast<long long>(std::llround(shared_m3 * 1e6))) +
                      " cm³ with static object \"" + a.entity->id + "\" (" + a.entity->pointer + ")");
      }
    }
  }
}

}  // namespace rigger::cell::detail
