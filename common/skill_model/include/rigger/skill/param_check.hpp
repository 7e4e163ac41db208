#pragma once
/// Checking the parameters a recipe gives a leaf against the leaf's description.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/model_error.hpp"
#include "rigger/skill/skill_description.hpp"

namespace rigger::skill {

/// Outcome of check_params(): the parameters with defaults filled in and quantities converted to
/// their SI unit (valid only when `errors` is empty), and every error found.
struct ParamCheckResult {
  nlohmann::json params = nlohmann::json::object();
  std::vector<ModelError> errors;
  bool ok() const { return errors.empty(); }
};

/// Checks `params` (a JSON object, or null meaning {}) against `description`: unknown names,
/// missing required parameters, types, enum values, ranges, units. Error pointers are
/// `pointer_prefix` + "/" + parameter name (prefix is e.g. "/root/children/2/params").
/// Never throws.
ParamCheckResult check_params(const SkillDescription& description, const nlohmann::json& params,
                              const std::string& pointer_prefix = "");

}  // namespace rigger::skill
