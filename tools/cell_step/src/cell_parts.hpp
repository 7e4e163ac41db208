#pragma once
// The simulated cell's parts as shapes, sized from the cell file.

#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "rigger/cell_config/cell_file.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace rigger::cad {

struct CellPart {
  std::string object;     ///< entity id in the cell file ("load", "target", "part", "part_fixture")
  std::string file_name;  ///< "load.step"
  TopoDS_Shape shape_m;
  std::vector<parts::DrilledHole> holes;  ///< h1..h4 (none for the part and its fixture)
};

/// The load and the target with their box sizes from `cell`, and the part and its fixture when the cell
/// has them. Throws std::runtime_error when the cell file has no load or target or a model is not a box.
std::vector<CellPart> cell_parts(const cell::CellFile& cell);

/// Writes every part as `<dir>/<file_name>`.
void write_cell_parts(const std::vector<CellPart>& parts, const std::filesystem::path& dir);

}  // namespace rigger::cad
