#include "rigger/cad/parts.hpp"

#include "occt_util.hpp"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <TopTools_ListOfShape.hxx>
#include <gp_Ax2.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rigger::cad::parts {
namespace {

gp_Dir to_gp_dir(const Eigen::Vector3d& d) { return gp_Dir(d.x(), d.y(), d.z()); }

// A tool cylinder for a hole: from 1 mm above the entry (so the cut opens cleanly) to the bottom, or
// 1 mm beyond it for a through hole.
TopoDS_Shape drill(const DrilledHole& hole) {
  constexpr double kOvershoot = 0.001;
  const Eigen::Vector3d bottom = hole.entry_m - hole.depth_m * hole.axis;
  const Eigen::Vector3d start = hole.through ? Eigen::Vector3d(bottom - kOvershoot * hole.axis) : bottom;
  const double length = (hole.entry_m - start).norm() + kOvershoot;
  return BRepPrimAPI_MakeCylinder(gp_Ax2(to_gp_pnt(start), to_gp_dir(hole.axis)), hole.diameter_m / 2, length).Shape();
}

TopoDS_Shape cut_holes(const TopoDS_Shape& body, const std::vector<DrilledHole>& holes) {
  if (holes.empty()) {
    return body;
  }
  TopTools_ListOfShape arguments, tools;
  arguments.Append(body);
  for (const auto& hole : holes) {
    tools.Append(drill(hole));
  }
  BRepAlgoAPI_Cut cut;
  cut.SetArguments(arguments);
  cut.SetTools(tools);
  cut.Build();
  if (!cut.IsDone()) {
    throw std::runtime_error("drilling the holes failed");
  }
  return cut.Shape();
}

std::vector<DrilledHole> four_holes(double z_top, double diameter_m, double depth_m, bool through) {
  std::vector<DrilledHole> holes;
  for (const auto& [x, y] : {std::pair{-0.15, -0.10}, {0.15, -0.10}, {0.15, 0.10}, {-0.15, 0.10}}) {
    holes.push_back({{x, y, z_top}, Eigen::Vector3d::UnitZ(), diameter_m, depth_m, through});
  }
  return holes;
}

}  // namespace

TopoDS_Shape drilled_box(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const std::vector<DrilledHole>& holes) {
  const TopoDS_Shape body = BRepPrimAPI_MakeBox(to_gp_pnt(min_m), to_gp_pnt(max_m)).Shape();
  return cut_holes(body, holes);
}

std::vector<DrilledHole> plate_holes() {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  return {{{0.03, 0.02, 0.01}, z, 0.008, 0.01, true},
          {{0.17, 0.02, 0.01}, z, 0.008, 0.01, true},
          {{0.10, 0.08, 0.01}, z, 0.008, 0.01, true}};
}

TopoDS_Shape plate() { return drilled_box({0, 0, 0}, {0.2, 0.1, 0.01}, plate_holes()); }

std::vector<DrilledHole> block_holes() {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  return {{{0.03, 0.04, 0.05}, z, 0.010, 0.05, true},
          {{0.07, 0.04, 0.05}, z, 0.006, 0.02, false},
          {{0.10, 0.04, 0.015}, Eigen::Vector3d::UnitX(), 0.005, 0.015, false}};
}

TopoDS_Shape block() { return drilled_box({0, 0, 0}, {0.1, 0.08, 0.05}, block_holes()); }

std::vector<DrilledHole> bracket_holes() {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  return {{{0.025, 0.025, 0.01}, z, 0.008, 0.01, true}, {{0.075, 0.025, 0.01}, z, 0.008, 0.01, true}};
}

TopoDS_Shape bracket() { return drilled_box({0, 0, 0}, {0.1, 0.05, 0.01}, bracket_holes()); }

Eigen::Isometry3d test_assembly_pose(const std::string& instance) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (instance == "frame_1") {
    pose.translation() = Eigen::Vector3d(1.0, 0, 0);
  } else if (instance == "pair_1") {
    pose.translation() = Eigen::Vector3d(0, 1.0, 0);
    pose.linear() = turned;
  } else if (instance == "plate_1") {
    pose.translation() = Eigen::Vector3d(0.3, 0, 0);
    pose.linear() = turned;
  } else if (instance == "bracket_1") {
    pose.translation() = Eigen::Vector3d(0, 0, 0.05);
  } else if (instance == "block_right") {
    pose.translation() = Eigen::Vector3d(0.2, 0, 0);
  }
  return pose;
}

std::vector<AssemblyProduct> test_assembly() {
  using C = AssemblyProduct::Component;
  const auto at = [](const std::string& instance, int product) { return C{instance, product, test_assembly_pose(instance)}; };
  return {{"cell_assembly", {}, {at("frame_1", 1), at("pair_1", 2)}},
          {"frame", {}, {at("plate_1", 3), at("bracket_1", 4)}},
          {"pair", {}, {at("block_left", 5), at("block_right", 5)}},
          {"plate", plate(), {}},
          {"bracket", bracket(), {}},
          {"block", block(), {}}};
}

std::vector<AssemblyProduct> test_assembly_with_a_sheet() {
  std::vector<AssemblyProduct> products = test_assembly();
  products[0].components.push_back({"sheet_1", static_cast<int>(products.size()), Eigen::Isometry3d::Identity()});
  products.push_back({"sheet", BRepBuilderAPI_MakeFace(gp_Pln(), 0, 0.1, 0, 0.1).Shape(), {}});
  return products;
}

std::vector<DrilledHole> boss_part_holes() { return {{{0.02, 0.02, 0.01}, Eigen::Vector3d::UnitZ(), 0.006, 0.01, true}}; }

TopoDS_Shape boss_part() {
  const TopoDS_Shape base = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(0.1, 0.1, 0.01)).Shape();
  const TopoDS_Shape boss = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.05, 0.05, 0.01), gp::DZ()), 0.01, 0.015).Shape();
  BRepAlgoAPI_Fuse fuse(base, boss);
  if (!fuse.IsDone()) {
    throw std::runtime_error("fusing the boss failed");
  }
  return cut_holes(fuse.Shape(), boss_part_holes());
}

std::vector<DrilledHole> cell_load_holes(const Eigen::Vector3d& size_m) {
  return four_holes(size_m.z() / 2, 0.013, size_m.z(), true);
}

TopoDS_Shape cell_load(const Eigen::Vector3d& size_m) {
  return drilled_box(-size_m / 2, size_m / 2, cell_load_holes(size_m));
}

std::vector<DrilledHole> cell_target_holes() { return four_holes(0.0, 0.0102, 0.030, false); }

TopoDS_Shape cell_target(const Eigen::Vector3d& size_m) {
  const Eigen::Vector3d half(size_m.x() / 2, size_m.y() / 2, 0.0);
  return drilled_box(-half - Eigen::Vector3d(0, 0, size_m.z()), half, cell_target_holes());
}

}  // namespace rigger::cad::parts
