#pragma once
/// @file
/// Screw: the operator screws, the skill tells them where and how and waits for their confirmation.
///
///   lookup ──holes known──▶ prompt(hole 1) ──done──▶ prompt(hole 2) … ──done──▶ SUCCESS
///     │                        │ failed → SCREW_FAILED, abort → OPERATOR_ABORTED,
///     ▼                        ▼ no answer within timeout_per_hole_s → OPERATOR_TIMEOUT
///   BAD_PARAMS / the world model's code
///
/// lookup: for every hole ref ("target/h1": entity/feature id) the entity's CAD features (world model
/// FEATURES query: screw_holes[].screw_type, torque_nm) and the hole's position in "world" (feature pose
/// query); the params screw_type / torque_nm override the world model's when given (non-empty / > 0).
/// prompt: rigger/operator/prompt kind "screw", options ["done","failed","abort"], details_json
/// {"hole" (the feature id, "h1"), "hole_ref" ("target/h1"), "screw_type", "torque_nm", "position_m" (world)}, then the
/// rigger/operator/response with its prompt_id. The prompt is withdrawn (active=false) whenever the state is left:
/// answered, timed out, failed or shut down. PROGRESS per hole.
///
/// Safe stops: nothing moves (the operator holds the tools); prompt → the prompt is withdrawn.
/// Claims "operator". Pre: inserted($object,$target). Post: fastened($object,$target).
/// Failure codes: DEVICE_UNAVAILABLE, BAD_PARAMS (a hole ref that is not entity/feature, or a hole
/// without screw data), UNKNOWN_FEATURE (not a screw hole of its entity), the world model's code
/// (UNKNOWN_ENTITY, WORLD_UNREACHABLE, …), SCREW_FAILED, OPERATOR_ABORTED, OPERATOR_TIMEOUT.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

/// One hole to screw, as the operator is told.
struct ScrewHole {
  std::string ref;     ///< "target/h1"
  std::string entity;  ///< "target"
  std::string id;      ///< "h1"
  std::string screw_type;
  double torque_nm = 0.0;
  Eigen::Vector3d position_world_m = Eigen::Vector3d::Zero();
};

/// The screw data of hole `id` in an entity's features JSON (`screw_holes`: [{id, screw_type, torque_nm}]).
/// Returns an error text when the hole is not there.
std::string find_screw_hole(const nlohmann::json& features, const std::string& id, ScrewHole& hole);

/// Why Screw's per-hole params (torque_per_hole_nm, screw_type_per_hole; already checked against their
/// types) do not fit `holes` holes — each list empty or one entry per hole, each type at most 64 bytes —
/// naming the param's path ("/params/torque_per_hole_nm: expected 4 values, …"); "" when they fit.
std::string per_hole_problem(const nlohmann::json& params, std::size_t holes);

class ScrewSkill final : public Skill {
 public:
  static const skill::SkillDescription& describe();
  ScrewSkill();

  static constexpr std::chrono::seconds kWorldTimeout{2};
  /// Prompt options and their meaning.
  static constexpr const char* kDone = "done";
  static constexpr const char* kFailed = "failed";
  static constexpr const char* kAbort = "abort";

 private:
  void lookup();
  void lookup_next();
  void prompt();

  std::vector<ScrewHole> holes_;
  std::size_t lookup_index_ = 0;
  nlohmann::json features_ = nlohmann::json::object();  // entity -> features
  std::size_t current_ = 0;
};

}  // namespace rigger::skill_executor
