#include "rigger/skill/skill_description.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "skill_json_util.hpp"

namespace rigger::skill {
namespace {

using Json = nlohmann::json;

constexpr std::pair<SkillKind, std::string_view> kKindNames[] = {
    {SkillKind::kSkill, "skill"},
    {SkillKind::kMonitor, "monitor"},
    {SkillKind::kCondition, "condition"},
};

// A "$param" reference must name a parameter whose value grounds to a single word.
bool is_scalar_type(ParamType type) {
  return type != ParamType::kPose && type != ParamType::kStringList && type != ParamType::kNumberList;
}

bool is_word_type(ParamType type) {
  return type == ParamType::kString || type == ParamType::kFeatureRef || type == ParamType::kEnum ||
         type == ParamType::kObjectId;
}

void parse_predicates(const Json& json, const char* key, const std::string& pointer, const SkillDescription& d,
                      bool allow_negation, std::vector<Predicate>& out, std::vector<ModelError>& errors) {
  if (!json.contains(key)) {
    return;
  }
  const Json& list = json[key];
  const std::string list_pointer = pointer + "/" + key;
  if (!list.is_array()) {
    errors.push_back({list_pointer, "expected an array of predicates like \"attached(robot,$object)\", got " +
                                        detail::describe_json(list)});
    return;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item_pointer = list_pointer + "/" + std::to_string(i);
    if (!list[i].is_string()) {
      errors.push_back({item_pointer, "expected a predicate string, got " + detail::describe_json(list[i])});
      continue;
    }
    std::string why;
    auto predicate = parse_predicate(list[i].get<std::string>(), &why);
    if (!predicate) {
      errors.push_back({item_pointer, why});
      continue;
    }
    if (predicate->negated && !allow_negation) {
      errors.push_back({item_pointer, "a precondition cannot be negated: expected a fact that must hold "
                                      "(\"!\" deletes facts in postconditions only)"});
      continue;
    }
    bool references_ok = true;
    for (const auto& param : predicate->referenced_params()) {
      const ParamSpec* spec = d.find_param(param);
      if (spec == nullptr) {
        errors.push_back({item_pointer, "references unknown parameter \"$" + param + "\"; expected one of the "
                                        "declared parameters"});
        references_ok = false;
      } else if (!is_scalar_type(spec->type)) {
        errors.push_back({item_pointer, "references \"$" + param + "\" of type " + std::string(to_string(spec->type)) +
                                            "; expected a scalar parameter (string, feature_ref, enum, number, "
                                            "integer, boolean)"});
        references_ok = false;
      }
    }
    if (references_ok) {
      out.push_back(std::move(*predicate));
    }
  }
}

}  // namespace

std::string_view to_string(SkillKind kind) {
  for (const auto& [k, name] : kKindNames) {
    if (k == kind) {
      return name;
    }
  }
  return "unknown";
}

std::optional<SkillKind> skill_kind_from_string(std::string_view name) {
  for (const auto& [k, n] : kKindNames) {
    if (n == name) {
      return k;
    }
  }
  return std::nullopt;
}

const std::vector<std::string_view>& known_resources() {
  static const std::vector<std::string_view> kResources{"robot", "crane", "gripper", "camera", "operator"};
  return kResources;
}

const ParamSpec* SkillDescription::find_param(std::string_view param_name) const {
  for (const auto& p : params) {
    if (p.name == param_name) {
      return &p;
    }
  }
  return nullptr;
}

bool operator==(const SkillDescription& a, const SkillDescription& b) {
  return a.name == b.name && a.kind == b.kind && a.description == b.description && a.params == b.params &&
         a.resources == b.resources && a.preconditions == b.preconditions && a.postconditions == b.postconditions &&
         a.pausable == b.pausable;
}

Json to_json(const SkillDescription& d) {
  Json out = Json::object();
  out["name"] = d.name;
  out["kind"] = std::string(to_string(d.kind));
  if (!d.description.empty()) {
    out["description"] = d.description;
  }
  out["params"] = Json::array();
  for (const auto& p : d.params) {
    out["params"].push_back(to_json(p));
  }
  if (!d.resources.empty()) {
    out["resources"] = d.resources;
  }
  auto predicates = [](const std::vector<Predicate>& list) {
    Json array = Json::array();
    for (const auto& p : list) {
      array.push_back(p.to_string());
    }
    return array;
  };
  if (!d.preconditions.empty()) {
    out["preconditions"] = predicates(d.preconditions);
  }
  if (!d.postconditions.empty()) {
    out["postconditions"] = predicates(d.postconditions);
  }
  if (d.pausable) {
    out["pausable"] = true;
  }
  return out;
}

Parsed<SkillDescription> parse_description(const Json& json, const std::string& pointer) {
  Parsed<SkillDescription> result;
  auto& errors = result.errors;
  if (!json.is_object()) {
    errors.push_back({pointer, "expected a description object {\"name\", \"kind\", \"params\", …}, got " +
                                   detail::describe_json(json)});
    return result;
  }
  detail::check_keys(json, pointer,
                     {"name", "kind", "description", "params", "resources", "preconditions", "postconditions",
                      "pausable"},
                     errors);
  SkillDescription d;
  detail::read_identifier(json, "name", pointer, detail::IdentifierStyle::kPascal, d.name, errors);

  if (!json.contains("kind")) {
    errors.push_back({pointer, "missing \"kind\": expected \"skill\", \"monitor\" or \"condition\""});
  } else if (const auto kind =
                 json["kind"].is_string() ? skill_kind_from_string(json["kind"].get<std::string>()) : std::nullopt;
             !kind) {
    errors.push_back({pointer + "/kind", "expected \"skill\", \"monitor\" or \"condition\", got " +
                                             detail::describe_json(json["kind"])});
  } else {
    d.kind = *kind;
  }

  if (json.contains("description")) {
    if (json["description"].is_string()) {
      d.description = json["description"].get<std::string>();
    } else {
      errors.push_back({pointer + "/description", "expected a string, got " + detail::describe_json(json["description"])});
    }
  }

  if (json.contains("params")) {
    const Json& params = json["params"];
    if (!params.is_array()) {
      errors.push_back({pointer + "/params", "expected an array of parameter declarations, got " +
                                                 detail::describe_json(params)});
    } else {
      std::set<std::string> names;
      for (std::size_t i = 0; i < params.size(); ++i) {
        const std::string p_pointer = pointer + "/params/" + std::to_string(i);
        auto parsed = parse_param_spec(params[i], p_pointer);
        errors.insert(errors.end(), parsed.errors.begin(), parsed.errors.end());
        if (!parsed.value) {
          continue;
        }
        if (!names.insert(parsed.value->name).second) {
          errors.push_back({p_pointer + "/name", "duplicate parameter name \"" + parsed.value->name + "\""});
          continue;
        }
        d.params.push_back(std::move(*parsed.value));
      }
    }
  }

  if (json.contains("resources")) {
    const Json& resources = json["resources"];
    if (!resources.is_array()) {
      errors.push_back({pointer + "/resources", "expected an array of resource names, got " +
                                                    detail::describe_json(resources)});
    } else if (!resources.empty() && d.kind != SkillKind::kSkill) {
      errors.push_back({pointer + "/resources", std::string(to_string(d.kind)) +
                                                    "s claim no resources: they observe, they do not actuate"});
    } else {
      for (std::size_t i = 0; i < resources.size(); ++i) {
        const std::string r_pointer = pointer + "/resources/" + std::to_string(i);
        const Json& r = resources[i];
        const std::string expected = "expected one of " + detail::join(known_resources(), true) +
                                     " or \"$param\" naming a string, feature_ref or enum parameter";
        if (!r.is_string()) {
          errors.push_back({r_pointer, expected + ", got " + detail::describe_json(r)});
          continue;
        }
        const std::string name = r.get<std::string>();
        const bool known = std::find(known_resources().begin(), known_resources().end(), name) !=
                           known_resources().end();
        const ParamSpec* param = (!name.empty() && name.front() == '$') ? d.find_param(name.substr(1)) : nullptr;
        if (!known && (param == nullptr || !is_word_type(param->type))) {
          errors.push_back({r_pointer, expected + ", got \"" + name + "\""});
          continue;
        }
        if (std::find(d.resources.begin(), d.resources.end(), name) != d.resources.end()) {
          errors.push_back({r_pointer, "duplicate resource \"" + name + "\""});
          continue;
        }
        d.resources.push_back(name);
      }
    }
  }

  parse_predicates(json, "preconditions", pointer, d, /*allow_negation=*/false, d.preconditions, errors);
  if (d.kind == SkillKind::kMonitor && json.contains("postconditions") &&
      !(json["postconditions"].is_array() && json["postconditions"].empty())) {
    errors.push_back({pointer + "/postconditions", "monitors have no postconditions: they never succeed"});
  } else {
    parse_predicates(json, "postconditions", pointer, d, /*allow_negation=*/true, d.postconditions, errors);
  }

  if (json.contains("pausable")) {
    if (!json["pausable"].is_boolean()) {
      errors.push_back({pointer + "/pausable", "expected true or false, got " + detail::describe_json(json["pausable"])});
    } else if (json["pausable"].get<bool>() && d.kind != SkillKind::kSkill) {
      errors.push_back({pointer + "/pausable", std::string(to_string(d.kind)) +
                                                   "s are never paused: only skills hold devices to hold still"});
    } else {
      d.pausable = json["pausable"].get<bool>();
    }
  }

  if (errors.empty()) {
    result.value = std::move(d);
  }
  return result;
}

SkillDescription description_from_json(const Json& json) {
  auto parsed = parse_description(json);
  if (!parsed.ok()) {
    throw SkillModelError(std::move(parsed.errors), "invalid skill description");
  }
  return std::move(*parsed.value);
}

std::vector<std::string> resolve_resources(const SkillDescription& description, const Json& params) {
  std::vector<std::string> out;
  for (const auto& r : description.resources) {
    std::string resolved = r;
    if (!r.empty() && r.front() == '$') {
      const std::string name = r.substr(1);
      if (!params.is_object() || !params.contains(name) || !params[name].is_string()) {
        continue;
      }
      resolved = params[name].get<std::string>();
      // A feature reference claims its entity: "load/grasp_side" and "load" are the same load.
      const ParamSpec* spec = description.find_param(name);
      if (spec != nullptr && spec->type == ParamType::kFeatureRef) {
        resolved = resolved.substr(0, resolved.find('/'));
      }
    }
    if (std::find(out.begin(), out.end(), resolved) == out.end()) {
      out.push_back(std::move(resolved));
    }
  }
  return out;
}

}  // namespace rigger::skill
