#pragma once
/// @file
/// Placing an object by picks (the Planner's "Place", docs/console.md): a face of the object, at a picked
/// point, lies on a face of another object at a picked point — normals opposite, the object's face x
/// turned `turn_deg` about the support's normal from the support face's x. The CAD service gives both
/// face frames (its `face` frame rule); this computes the object's new pose in its parent's frame and the
/// cell document of the revision that puts it there. Free of HTTP and DDS, unit-tested.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "planner.hpp"

namespace rigger::console {

/// POST /api/planner/place: {"model": "object:<entity>", "face": F, "point_m": [x, y, z],
/// "onto": {"model": "object:<support>", "face": F2, "point_m": [...]}, "turn_deg": a, "comment"?}.
struct PlaceRequest {
  FrameRequest own;   ///< the object's face (rule "face")
  FrameRequest onto;  ///< the support's face (rule "face")
  /// Picked edges ("edge", "onto.edge": indices in the models' features), both or neither: the object is
  /// turned so that its edge lies along the support's, then by `turn_deg`.
  std::optional<int> own_edge, onto_edge;
  double turn_deg = 0.0;
  /// Moved this far along the support's face ("offset_m", at most 10 m either way): along its picked
  /// edge, else along the face's x.
  double offset_m = 0.0;
  /// true: the pose is known (no Localize needed); false: found by a Localize skill at run time, this
  /// being where the simulator starts it; none: as the cell said.
  std::optional<bool> localized;
  std::string comment;
};
/// @throws PlannerError naming the field (the support's under "/onto").
PlaceRequest parse_place_request(const nlohmann::json& body);

/// A frame the CAD service answered ({"frame": {"position_m", "rotation" (3x3 rows)}}) as a transform.
/// @throws PlannerError when the answer holds none.
Eigen::Isometry3d frame_from_cad(const nlohmann::json& cad_result);

/// The object's pose in the support's frame: its face frame `own_face` (in the object's frame) on the
/// support's `onto_face` (in the support's frame), normals opposite, turned about the support's normal.
Eigen::Isometry3d placed_on(const Eigen::Isometry3d& onto_face, const Eigen::Isometry3d& own_face, double turn_deg);

/// The turn about the support's normal (degrees) that lays the object's edge (direction `own_edge` in its
/// model frame) along the support's edge (`onto_edge`, in the support's frame) once the faces mate.
/// @throws PlannerError at "/edge" or "/onto/edge" when an edge does not lie in its face's plane.
double edge_turn_deg(const Eigen::Isometry3d& onto_face, const Eigen::Vector3d& onto_edge,
                     const Eigen::Isometry3d& own_face, const Eigen::Vector3d& own_edge);

/// The support's face frame moved `offset_m` along `direction` (in the support's frame, projected on the
/// face; none: the face's x).
Eigen::Isometry3d offset_along(const Eigen::Isometry3d& onto_face, const std::optional<Eigen::Vector3d>& direction,
                               double offset_m);

/// The entity's pose in the world, through the document's parents.
/// @throws PlannerError when an entity is missing or the parents do not reach "world".
Eigen::Isometry3d world_pose_of(const nlohmann::json& cell, const std::string& id);

/// {"position_m", "rpy_deg"} of a pose (R = Rz Ry Rx, the cell file's), nanometres and micro-degrees.
nlohmann::json position_rpy(const Eigen::Isometry3d& pose);

/// The cell document `cell` with `entity` moved to `support_T_entity` (in `support`'s frame): its pose
/// written in its own parent's frame, the chain of parents resolved through the document's poses, and
/// its `localized` set when given.
/// @throws PlannerError when an entity is missing, an object is placed on itself or on what it carries,
/// or a parent chain does not reach "world".
nlohmann::json cell_with_placement(const nlohmann::json& cell, const std::string& entity, const std::string& support,
                                   const Eigen::Isometry3d& support_T_entity,
                                   std::optional<bool> localized = std::nullopt);

/// POST /api/planner/add: {"model": "sha256:<hex>" (an imported file), "id": "<the new object's id>",
/// "material": "steel" | "aluminium" | "plastic" (loose, its mass the model's volume times the density)
/// | "fixed" (static, fixed to the floor), "comment"?}.
struct AddRequest {
  std::string sha256;
  std::string id;
  std::string material;
  std::string comment;
};
/// @throws PlannerError naming the field.
AddRequest parse_add_request(const nlohmann::json& body);

/// POST /api/planner/import/node: {"model": "sha256:<hex>" (an imported file), "node": [i, j, ...] (the
/// path in its product tree from the root: the index of the component taken at each level, at most 32)}.
struct NodeRequest {
  std::string sha256;
  std::vector<int> node;
};
/// @throws PlannerError naming the field.
NodeRequest parse_node_request(const nlohmann::json& body);

/// The model.step of the object an imported file becomes: "imported/<id>.step".
std::string imported_model_name(const std::string& id);

/// The lowest z of the vertices in the CAD service's features answer (entities included), in the model's
/// frame. @throws PlannerError when the answer has no vertex.
double lowest_vertex_z(const nlohmann::json& features);

/// The cell document `cell` with a new object: the imported model as `imported/<id>.step` pinned by its
/// sha256, standing on the floor (its lowest point `lowest_z_m` at z = 0; 1 mm above when loose) 1 m
/// beyond every entity placed in the world along x, where Place can then put it.
/// @throws PlannerError at "/id" when an entity of that id exists.
nlohmann::json cell_with_new_object(const nlohmann::json& cell, const AddRequest& request, double lowest_z_m);

/// The crane's load exchanged: `part` takes the hook from `holder` (the object the rope hooked) and `holder` is
/// set down where `part` stood. `part` hangs level as it stands now (its orientation kept), its rope
/// attachment `attachment_m` (in its model frame) straight under the hook (the holder's attachment) and its
/// lowest point as high as the holder's was; it is not localized there (a Localize finds it). The holder,
/// its orientation kept, stands with its origin above where `part`'s was and its lowest point where `part`'s
/// was. The lowest points come from the models' vertices (`*_features`: the CAD service's features answers).
/// @throws PlannerError when an entity is missing or has no pose, or a model has no vertex.
nlohmann::json cell_with_load_exchanged(const nlohmann::json& cell, const std::string& part,
                                        const Eigen::Vector3d& attachment_m, const nlohmann::json& part_features,
                                        const std::string& holder, const nlohmann::json& holder_features);

}  // namespace rigger::console
