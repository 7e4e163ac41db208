#pragma once
/// @file
/// What cell_sim does with a revision of the cell (rigger/world/cell, common/cell_follower): the free
/// objects it moves (each put at its new pose at rest, on the physics thread), whether the physics model is
/// built anew from the revision (objects added, removed or reshaped), or why it cannot take the revision.
/// Pure: no DDS, no physics.
///
/// Taken: a revision that, against the cell cell_sim runs on, moves objects, adds, removes or reshapes
/// objects (their model, features or markers), moves a static object, changes only what the physics
/// does not use (`localized`, `comment`, `description`, `attributes`), mounts, changes or unmounts the
/// robot's calibration board (a geom of the gripper: the model is built anew), or moves a camera. A camera's move
/// is a new drawing of where it is (a calibration's result): the camera itself stays where it was bolted
/// (the start's drawing times camera/pose_error) and renders from there; only what the cell says of it
/// changes. Refused, with the reason: one that moves any other device, changes, adds or removes a device,
/// or removes, reshapes or replaces the crane's load (it hangs from the rope). Whether the model can be
/// swapped now (the arm at rest, the magnet holding nothing) and each moved object moved (free, not on the
/// rope, not in the magnet) is the physics' to say when it applies the plan.

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

/// The moves to make (free objects of the next cell), whether the model is built anew from the next cell
/// first, or (refusal not empty) why the revision is refused.
struct RevisionPlan {
  std::vector<ObjectMove> moves;
  bool rebuild = false;
  /// What makes the rebuild, for the log: "adds part_b; removes part; reshapes bracket".
  std::string rebuild_reason;
  /// Cameras the revision draws elsewhere (moved devices with a camera block): nothing in the simulation
  /// moves; the camera renders from its true pose as before.
  std::vector<std::string> cameras_redrawn;
  std::string refusal;
};

/// Plans the move from `running` to `next` given what changed (`changes`, in the form of cell::diff_cells;
/// cell_sim diffs against its own running cell, so that it can follow from any revision, also after a
/// restart on its cell file).
RevisionPlan plan_revision(const nlohmann::json& changes, const cell::CellFile& running, const cell::CellFile& next);

}  // namespace rigger::cell_sim
