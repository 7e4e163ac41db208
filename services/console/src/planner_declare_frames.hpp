#pragma once
/// @file
/// Features declared by picks whose poses come from a CAD frame rather than a rule the cell file derives:
/// the rope attachment (a picked hole: its entry, z along its axis out; a face at the picked point, z out of
/// it; or a sling's ring above the part's centre of mass) and fiducial markers (a square of a dictionary id and size on a picked face, centred at the
/// picked point, z out of the face, x the model's x projected on it). The console asks the CAD service for
/// the frame (and, for a marker, checks that its four corners lie on the face); these write the pose into
/// the running cell document. Free of HTTP and DDS, unit-tested.
#include <array>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "planner_declare.hpp"

namespace rigger::console {

/// The object of `cell` other than `except` that has a rope attachment (the crane's load), or "".
std::string rope_holder(const nlohmann::json& cell, const std::string& except);

/// The CAD_FRAME args for the request's pick: {"rule": "hole", "hole"}, {"rule": "face", "face", "point_m"}, or
/// for a rope attachment with "above_centre_of_mass": true, {"rule": "above_centre_of_mass"} (a sling).
/// @throws PlannerError naming the field (a marker needs a face and a point).
nlohmann::json frame_args(const DeclareRequest& request);

/// The four corner points (model frame) of the marker the request declares, on the face frame `at`.
std::array<Eigen::Vector3d, 4> marker_corners(const DeclareRequest& request, const Eigen::Isometry3d& at);

/// The cell document with the rope attachment or the marker at `at` (in the entity's model frame).
/// {"cell", "features": [ids], "rule": [the new entry]}.
/// @throws PlannerError when the entity has a rope attachment already or is fixed (a rope's), its markers are of another
/// dictionary, the marker id is not in the dictionary or is on an object of the cell already.
nlohmann::json declare_at_frame(const DeclareRequest& request, const nlohmann::json& cell, const Eigen::Isometry3d& at);

/// What the cell's cameras will make of a marker at `at` (in `entity`'s model frame) where the part stands now:
/// "" when a camera sees its face within 60 degrees of its normal (the tracker's good viewing angle), else a
/// sentence naming the nearest angle (the tracker weighs a marker down past 60 degrees, and not at all past 85: a
/// pose from it is poor or none). A camera is an entity with a "camera" block.
std::string marker_view_note(const nlohmann::json& cell, const std::string& entity, int marker_id,
                             const Eigen::Isometry3d& at);

}  // namespace rigger::console
