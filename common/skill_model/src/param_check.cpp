#include "rigger/skill/param_check.hpp"

#include "skill_json_util.hpp"

namespace rigger::skill {

ParamCheckResult check_params(const SkillDescription& description, const nlohmann::json& params,
                              const std::string& pointer_prefix) {
  ParamCheckResult result;
  if (!params.is_null() && !params.is_object()) {
    result.errors.push_back({pointer_prefix, "expected an object of parameters, got " + detail::describe_json(params)});
    return result;
  }
  std::vector<std::string> declared;
  for (const auto& spec : description.params) {
    declared.push_back(spec.name);
  }
  if (params.is_object()) {
    for (const auto& item : params.items()) {
      if (description.find_param(item.key()) == nullptr) {
        result.errors.push_back(
            {pointer_prefix + "/" + escape_pointer_token(item.key()),
             "unknown parameter \"" + item.key() + "\" of " + std::string(to_string(description.kind)) + " " +
                 description.name + "; expected " +
                 (declared.empty() ? std::string("no parameters") : "one of " + detail::join(declared, true))});
      }
    }
  }
  for (const auto& spec : description.params) {
    const std::string pointer = pointer_prefix + "/" + escape_pointer_token(spec.name);
    if (!params.is_object() || !params.contains(spec.name)) {
      if (spec.default_value) {
        result.params[spec.name] = *spec.default_value;
      } else {
        result.errors.push_back({pointer, "missing required parameter \"" + spec.name + "\" of " +
                                              std::string(to_string(description.kind)) + " " + description.name +
                                              ": expected " + describe_expectation(spec)});
      }
      continue;
    }
    nlohmann::json normalized;
    auto errors = check_value(spec, params[spec.name], pointer, &normalized);
    if (errors.empty()) {
      result.params[spec.name] = std::move(normalized);
    } else {
      result.errors.insert(result.errors.end(), errors.begin(), errors.end());
    }
  }
  return result;
}

}  // namespace rigger::skill
