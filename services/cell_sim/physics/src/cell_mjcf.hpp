#pragma once
// Internal: the cell's MuJoCo model generated from the device MJCF and the cell file's objects.

#include <filesystem>
#include <string>

#include "cell_model.hpp"
#include "rigger/sim/cell_geometry.hpp"

namespace rigger::sim::detail {

/// The device MJCF text with the cell's objects inserted at its markers: one body per object, named by
/// the entity id (the load hung from the crane's hook by a ball joint "<id>_swivel" with a site
/// "<id>_rope_attachment", static objects fixed to the world, the others free with a joint "<id>_free");
/// a box geom named by the id, or one convex mesh geom per STEP solid ("<id>_solid<k>", mass shared by
/// the solids' volumes). Throws PhysicsModelError when a marker is missing.
std::string cell_mjcf(std::string device_xml, const CellGeometry& cell, const std::filesystem::path& device_path);

/// Reads the device MJCF, generates the cell's model and compiles it from memory.
/// Throws PhysicsModelError with MuJoCo's message.
ModelPtr load_cell_model(const std::filesystem::path& device_path, const CellGeometry& cell);

}  // namespace rigger::sim::detail
