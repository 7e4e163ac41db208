#pragma once
/// The description of a skill, monitor or condition: what executors announce, what the task
/// controller validates recipes against, what riggerctl shows.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/model_error.hpp"
#include "rigger/skill/param_spec.hpp"
#include "rigger/skill/predicate.hpp"

namespace rigger::skill {

/// What a leaf of the behaviour tree is.
enum class SkillKind {
  kSkill,      ///< acts on the world; reports SUCCESS or FAILURE
  kMonitor,    ///< watches; never succeeds, reports FAILURE when it detects an anomaly
  kCondition,  ///< a question to the world model; true (SUCCESS) or false (FAILURE) at once
};

/// "skill", "monitor", "condition".
std::string_view to_string(SkillKind kind);
/// Inverse of to_string(SkillKind); std::nullopt for an unknown name.
std::optional<SkillKind> skill_kind_from_string(std::string_view name);

/// Resources a skill may claim. A resource entry is one of these words or "$param", which claims
/// the value of that (string or feature_ref) parameter — e.g. "$object" claims "load" when the
/// recipe passes object = "load". Two branches of a Parallel may not claim the same resource.
const std::vector<std::string_view>& known_resources();

struct SkillDescription {
  std::string name;  ///< [A-Z][A-Za-z0-9_]*, unique in a library across kinds
  SkillKind kind = SkillKind::kSkill;
  std::string description;
  std::vector<ParamSpec> params;
  /// Exclusively claimed while the leaf runs: entries of known_resources() or "$param".
  /// Monitors and conditions claim nothing (they observe, they do not actuate).
  std::vector<std::string> resources;
  /// Facts that must hold before the leaf starts (no "!"; arguments may be "$param").
  std::vector<Predicate> preconditions;
  /// Facts that hold after it succeeded; "!p(...)" deletes a fact. Monitors have none.
  std::vector<Predicate> postconditions;
  /// Whether a PAUSE holds the leaf's devices still until RESUME (skills only). A leaf that is not
  /// pausable keeps running while its task is paused (monitors keep monitoring).
  bool pausable = false;

  /// The parameter declaration named `name`, or nullptr.
  const ParamSpec* find_param(std::string_view param_name) const;
  friend bool operator==(const SkillDescription& a, const SkillDescription& b);
};

/// The JSON form:
/// {"name", "kind", "description"?, "params": [ParamSpec…], "resources": [...]?,
///  "preconditions": ["p(...)", …]?, "postconditions": ["p(...)", "!q(...)", …]?, "pausable": true?}
nlohmann::json to_json(const SkillDescription& description);

/// Parses and checks a description without throwing; `pointer` prefixes error pointers.
/// Checks: shape and types, name syntax, unique parameter names, coherent parameter
/// declarations, resources known or "$param" of a string/feature_ref/enum parameter, predicates
/// parse and reference existing scalar parameters, no "!" in preconditions, monitors and
/// conditions claim no resources, monitors have no postconditions, only skills are pausable.
Parsed<SkillDescription> parse_description(const nlohmann::json& json, const std::string& pointer = "");

/// Throwing form of parse_description() for setup code. Throws SkillModelError with every error.
SkillDescription description_from_json(const nlohmann::json& json);

/// The resources a leaf claims with these (checked, defaults filled) parameters: "$param"
/// entries replaced by the parameter's string value (a feature_ref claims its entity: "$grasp" =
/// "load/grasp_side" claims "load"). Duplicates removed, order kept.
std::vector<std::string> resolve_resources(const SkillDescription& description, const nlohmann::json& params);

}  // namespace rigger::skill
