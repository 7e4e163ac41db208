#pragma once
/// @file
/// What cell_sim does with a revision of the cell (rigger/world/cell, common/cell_follower): the free
/// objects it moves (each put at its new pose at rest, on the physics thread), or why it cannot take the
/// revision. Pure: no DDS, no physics.
///
/// Taken: a revision that, against the cell cell_sim runs on, moves objects, or changes only what the
/// physics does not use (`localized`, `comment`, `description`, `attributes`). Refused, with the reason:
/// one that moves a device, or adds, removes
/// or reshapes an object (the model is built at start: cell_sim takes such a cell when restarted on it).
/// Whether each moved object can be moved (free, not on the rope, not in the magnet) is the physics'
/// to say when it applies the moves.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rigger/cell_follower/cell_revision.hpp"

namespace rigger::cell_sim {

/// One object put at a new pose: its entity frame in the world.
struct ObjectMove {
  std::string id;
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
};

/// The moves to make, or (refusal not empty) why the revision is refused.
struct RevisionPlan {
  std::vector<ObjectMove> moves;
  std::string refusal;
};

/// Plans the move to `next` given what changed from the cell cell_sim runs on (`changes`, in the form of
/// cell::diff_cells; cell_sim diffs against its own running cell, so that it can follow from any revision,
/// also after a restart on its cell file).
RevisionPlan plan_revision(const nlohmann::json& changes, const cell::CellFile& next);

}  // namespace rigger::cell_sim
