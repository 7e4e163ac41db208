#pragma once
/// @file
/// A feature declared by picks (docs/console.md, "Planner", "Declare a feature"): the cell-file rule of a
/// grasp frame, an approach waypoint or screw holes, built from the CAD service's own references (kind,
/// index, signature) of the picked face, edge or hole, and the running revision's cell document with
/// that feature added. Free of HTTP and DDS; the endpoint submits the document as a revision dry run.
#include <string>

#include <nlohmann/json.hpp>

#include "planner.hpp"

namespace rigger::console {

/// POST /api/planner/declare: {"model": "object:<entity>", "kind", "name", ...the kind's picks}:
///   "grasp_frame":       "face" (a planar face's index), optional "x_edge" (a straight edge in it),
///                        "x_reversed" (bool); z goes into the face (the way the tool approaches it)
///   "approach_waypoint": the same picks and "standoff_m" (> 0, at most 2 m) out of the face
///   "screw_holes":       "hole" (a hole's index in the CAD features), "like" (bool: every hole of the
///                        same diameter and axis on the same face as well), "screw" {"screw_type",
///                        "torque_nm"} for each, optional "screws" [{...}] one per hole in hole order
///   "insertion":         "face" (this object's planar face that mates) and "target" {"model":
///                        "object:<target>", "face"} (the target's); "name" may be left out
///   "rope_attachment":   "hole", or "face" and "point_m" (planner_declare_frames.hpp)
///   "marker":            "face", "point_m", "dictionary", "marker_id", "size_m" (planner_declare_frames.hpp)
/// A screw-hole name is a prefix: the holes become <name>1, <name>2, ...
struct DeclareRequest {
  std::string model;   ///< "object:target"
  std::string entity;  ///< "target"
  std::string kind;
  std::string name;
  std::string target;    ///< insertion: the entity it is inserted into
  nlohmann::json picks;  ///< the body, checked for the kind's fields
};
/// @throws PlannerError naming the field.
DeclareRequest parse_declare_request(const nlohmann::json& body);

/// The cell document `cell` with the declared feature added to `request.entity`'s features, its
/// references taken from `cad_features` (the CAD service's CAD_FEATURES `result` of the entity's model:
/// "faces", "edges", "holes"). {"cell": document, "features": [the new features' ids], "rule": [the new
/// entries]}.
/// @throws PlannerError when the picks make no such feature (not a plane, an edge not in the face, an
/// index the model does not have) or the name is taken. Screw holes "like" the picked one are those of its
/// diameter and axis on its entry plane: a face with holes of two diameters gives two patterns.
/// An insertion ({"face", "target": {"model": "object:<target>", "face"}}) mates a face of the object on a
/// face of the target (`target_cad_features`: the target model's) as the `mate_faces` rule; an object has
/// one insertion.
nlohmann::json declare_feature(const DeclareRequest& request, const nlohmann::json& cell,
                               const nlohmann::json& cad_features,
                               const nlohmann::json& target_cad_features = nlohmann::json::object());

}  // namespace rigger::console
