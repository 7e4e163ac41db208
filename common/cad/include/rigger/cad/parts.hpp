#pragma once
/// @file
/// Parts built with OCCT from known dimensions (metres): the test parts of rigger_cad's unit tests and
/// the load and target of the simulated cell (tools/cad_parts writes them as STEP).

#include "rigger/cad/assembly.hpp"

#include <Eigen/Core>
#include <TopoDS_Shape.hxx>

#include <vector>

namespace rigger::cad::parts {

/// A drilled hole as built: axis out of the hole, entry on the surface.
struct DrilledHole {
  Eigen::Vector3d entry_m;
  Eigen::Vector3d axis;  ///< unit, pointing out of the material
  double diameter_m;
  double depth_m;  ///< for through holes, the thickness drilled
  bool through;
};

/// A box [min, max] with the given holes drilled (flat-bottomed blind holes or through holes).
TopoDS_Shape drilled_box(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const std::vector<DrilledHole>& holes);

/// Plate 200 x 100 x 10 mm at the origin, three through holes of 8 mm.
std::vector<DrilledHole> plate_holes();
TopoDS_Shape plate();

/// Block 100 x 80 x 50 mm: a 10 mm through hole (z), a 6 mm blind hole 20 mm deep from the top, and a
/// 5 mm blind hole 15 mm deep along -x from the +x side.
std::vector<DrilledHole> block_holes();
TopoDS_Shape block();

/// Plate 100 x 100 x 10 mm with a 20 mm boss 15 mm high on top (not a hole) and one 6 mm through hole.
std::vector<DrilledHole> boss_part_holes();
TopoDS_Shape boss_part();

/// The simulated cell's load: a box of `size_m` (the cell file's, 0.40 x 0.30 x 0.20 m) about its centre
/// with four 13 mm through holes (M12 clearance) at (±0.15, ±0.10), in the order h1 (-,-), h2 (+,-),
/// h3 (+,+), h4 (-,+).
std::vector<DrilledHole> cell_load_holes(const Eigen::Vector3d& size_m);
TopoDS_Shape cell_load(const Eigen::Vector3d& size_m);

/// The simulated cell's target: a box of `size_m` (0.50 x 0.40 x 0.95 m) with its frame at the centre of
/// the top face, four blind 10.2 mm holes (M12 tap drill) 30 mm deep at (±0.15, ±0.10): h1..h4 as for
/// the load.
std::vector<DrilledHole> cell_target_holes();
TopoDS_Shape cell_target(const Eigen::Vector3d& size_m);

/// Bracket 100 x 50 x 10 mm at the origin, two through holes of 8 mm.
std::vector<DrilledHole> bracket_holes();
TopoDS_Shape bracket();

/// An assembly for tests (write_step_assembly; products[0] is the root): "cell_assembly" holds
///  - "frame_1" at x = 1 m, the sub-assembly "frame": "plate_1" (plate()) turned 90° about z at x = 0.3 m,
///    and "bracket_1" (bracket()) 50 mm up: 5 holes, x in [0, 0.3], y in [0, 0.2], z in [0, 0.06];
///  - "pair_1" at y = 1 m turned 90° about z, the sub-assembly "pair": the one product "block" used twice,
///    "block_left" at its origin and "block_right" 0.2 m along x.
std::vector<AssemblyProduct> test_assembly();
/// The pose of each part instance of test_assembly() in its sub-assembly's frame, by instance name.
Eigen::Isometry3d test_assembly_pose(const std::string& instance);
/// test_assembly() with a third component at the root, "sheet_1": the product "sheet", one face of
/// 0.1 x 0.1 m and no solid (a node that cannot be an object).
std::vector<AssemblyProduct> test_assembly_with_a_sheet();

}  // namespace rigger::cad::parts
