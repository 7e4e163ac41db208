#pragma once
// Internal: the cell file's objects as the physics builds them (ObjectGeometry), read from their STEP
// models with OpenCascade.

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rigger/cad/model.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/sim/cell_geometry.hpp"

namespace rigger::sim::detail {

/// The object entity's body: its pose, static or free, its box or its STEP solids (tessellated, one convex
/// hull each), its mass. STEP paths are relative to `model_dir`; `read_models` (entity id -> model) holds
/// models already read (by the CAD rules' derivation), which are not read again.
/// @throws cell::CellFileError at ".../model" (no geometry), ".../model/mass_kg" (a free object without a
///   mass), ".../model/step" (unreadable, empty, or a solid that is not closed or has no volume).
ObjectGeometry object_geometry_from(const cell::CellFile& file, const cell::CellEntity& entity,
                                    const std::filesystem::path& model_dir,
                                    const std::map<std::string, cad::Model>& read_models);

/// cell_geometry_from with the models the derivation already read.
CellGeometry cell_geometry_with_models(const cell::CellFile& file, const std::filesystem::path& model_dir,
                                       const std::map<std::string, cad::Model>& read_models);

/// {centre, full size} of the vertices' bounding box.
std::pair<Eigen::Vector3d, Eigen::Vector3d> vertex_bounds(const std::vector<ObjectSolid>& solids);

}  // namespace rigger::sim::detail
