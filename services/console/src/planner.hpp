#pragma once
/// @file
/// The logic behind the planner's endpoints (docs/console.md, "Planner"), free of HTTP and DDS so that
/// it can be unit-tested: the live skill library the executors announce, recipe validation by the
/// controller's own validator (rigger_recipe), and the screw list of picked holes: the CAD service's
/// derivation matched to the world model's screw-hole features.
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/skill_library.hpp"

namespace rigger::console {

/// A planner request refused: `pointer` names the offending part of the request body (JSON pointer,
/// "" = the whole body) and `message` says what was expected.
struct PlannerError {
  std::string pointer;
  std::string message;
};

/// The hex sha256 of the imported file a request body names as "model": "sha256:<hex>".
/// @throws PlannerError at "/model" for anything else.
std::string imported_model_sha256(const nlohmann::json& body);

/// The skill library as the controller builds it: every live executor's announced library merged,
/// plus the conditions the controller answers itself. Thread-safe (the DDS loop updates, HTTP reads).
class SkillCatalog {
 public:
  /// An executor's announcement (`alive`, its library_json text) or its departure (`alive` false).
  void update(const std::string& executor_id, bool alive, const std::string& library_json);
  /// The merged library. Libraries that do not parse or conflict are left out (see to_json()).
  skill::SkillLibrary library() const;
  /// {"skills": [description, ...] (by name), "executors": {id: [skill names]}, "problems": [text]}.
  nlohmann::json to_json() const;

 private:
  skill::SkillLibrary merged(std::vector<std::string>* problems) const;
  mutable std::mutex mutex_;
  std::map<std::string, nlohmann::json> libraries_;  ///< live executors only
};

/// Validates recipe `text` against `library` with the task controller's validator (bounded parsing,
/// schema, semantics: exactly what the controller will say): {"ok": bool, "errors": [{"pointer",
/// "message"}], "canonical": text}. `canonical` (present when the text parses) is the recipe with its
/// keys sorted at every level and two-space indentation, ending in a newline: the same recipe always
/// gives the same text, so exported recipes diff cleanly.
nlohmann::json validate_recipe(const skill::SkillLibrary& library, std::string_view text);

/// The canonical text of a JSON document (see validate_recipe()).
std::string canonical_json(const nlohmann::json& document);

/// POST /api/planner/screws: {"model": "object:<entity>", "holes": [<hole index or face reference>, ...]}.
struct ScrewRequest {
  std::string model;   ///< "object:target"
  std::string entity;  ///< "target"
  nlohmann::json holes;
};
/// @throws PlannerError naming the field.
ScrewRequest parse_screw_request(const nlohmann::json& body);

/// The CAD service's screw list (CAD_DERIVE screw_list `result`) with each screw matched to the world
/// model's screw-hole feature of `entity` whose position is within `tolerance_m` of the hole's entry
/// (both in the entity's frame, which is its STEP model's frame): each screw gets "feature"
/// ("target/h1"), and that feature's "screw_type" and "torque_nm" as defaults.
/// {"model", "model_sha256", "entity", "screws": [{"hole", "ref", "feature", "pose", "diameter_m",
/// "depth_m", "through", "screw_type", "torque_nm"}]}.
/// @throws PlannerError when a hole has no screw-hole feature there (saying which is nearest).
nlohmann::json screws_with_features(const ScrewRequest& request, const std::string& model_sha256,
                                    const nlohmann::json& cad_result, const nlohmann::json& world_entity,
                                    double tolerance_m = 1e-3);

/// POST /api/planner/frame: a pose parameter from picks, by one of the CAD service's frame rules:
/// {"model": "object:<entity>", "rule": "edges", "point_m": [x, y, z], "edges": [E1, E2]} (the paper's
/// point and two perpendicular edges), {"rule": "face", "face": F, "point_m": [...]} or
/// {"rule": "hole", "hole": H}; an edge or face is an index or a reference object, a point is in the
/// model's frame (metres).
struct FrameRequest {
  std::string model;   ///< "object:target"
  std::string entity;  ///< "target"
  nlohmann::json args;  ///< CAD_FRAME args_json: only the rule's own fields
};
/// @throws PlannerError naming the field.
FrameRequest parse_frame_request(const nlohmann::json& body);

/// The pose parameter of a CAD frame (CAD_FRAME `result`: {"frame": {"position_m", "rotation"}}), in
/// the entity's frame (its STEP model's frame): {"position_m", "rpy_deg", "frame": entity}, with
/// R = Rz(yaw) Ry(pitch) Rx(roll) as everywhere in rigger (at pitch ±90° roll is 0).
/// @throws PlannerError when the answer holds no frame.
nlohmann::json pose_from_cad_frame(const nlohmann::json& cad_result, const std::string& entity);

}  // namespace rigger::console
