#pragma once
/// @file
/// What the world model's JSON says of an object whose geometry is its STEP model alone (no `shape`):
/// the shape kind "step" and the model's bounding box, so the console and tools can draw it.

#include <filesystem>
#include <map>
#include <string>

#include "rigger/cad/model.hpp"
#include "world_cell_config.hpp"

namespace rigger::world {

/// Sets `shape` "step" and `size_m` to the extents of the STEP model's axis-aligned bounding box in the
/// entity frame (metres) for every object with a STEP model and no shape. Models in `read_models`
/// (by entity id: cell::CadDerivation::read_models) are not read again; the others are read from
/// `model_dir` (the cell file's folder).
/// @throws CellConfigError naming the file, the JSON pointer of the model and why it cannot be read.
void describe_step_models(CellConfig& cell, const std::map<std::string, cad::Model>& read_models,
                          const std::filesystem::path& model_dir);

}  // namespace rigger::world
