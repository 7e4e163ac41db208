#pragma once
/// @file
/// Static objects may touch, not overlap: the physics cannot push fixed bodies apart, so an overlap is a
/// drawing error that would show only as objects jumping off them. load_cell_file checks boxes among
/// themselves (box against box, exact); this checks every pair of static objects of which one at least is
/// given by its STEP model, by the volume the two solids share (OpenCascade's Boolean common).

#include <functional>

#include "rigger/cad/model.hpp"
#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell::detail {

/// Shared volume above which two static objects overlap: 1 cm³ (a 1 mm overlap over a 10 cm × 1 cm strip).
inline constexpr double kMaxSharedVolume_m3 = 1e-6;

/// @param model_of the STEP model of an object given by one (read once by the caller).
/// @throws CellFileError at the later object's "/pose", naming the other object and the shared volume.
void check_static_solids_apart(const CellFile& file, const std::function<const cad::Model&(const CellEntity&)>& model_of);

}  // namespace rigger::cell::detail
