#include "rigger/skill/param_spec.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include "rigger/skill/units.hpp"
#include "skill_json_util.hpp"

namespace rigger::skill {
namespace {

using Json = nlohmann::json;

constexpr std::array<std::pair<ParamType, std::string_view>, 10> kTypeNames{{
    {ParamType::kNumber, "number"},
    {ParamType::kInteger, "integer"},
    {ParamType::kBoolean, "boolean"},
    {ParamType::kString, "string"},
    {ParamType::kEnum, "enum"},
    {ParamType::kPose, "pose"},
    {ParamType::kFeatureRef, "feature_ref"},
    {ParamType::kStringList, "string_list"},
    {ParamType::kObjectId, "object_id"},
    {ParamType::kNumberList, "number_list"},
}};

// Has a unit and bounds its values (a number_list each of its numbers).
bool is_numeric(ParamType type) {
  return type == ParamType::kNumber || type == ParamType::kInteger || type == ParamType::kNumberList;
}
bool is_sized(ParamType type) {
  return type == ParamType::kString || type == ParamType::kStringList;
}

bool is_atom_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
}

bool is_object_id(const std::string& text) {
  if (text.empty() || text.size() > 64) return false;
  for (const char c : text) {
    if (!is_atom_char(c)) return false;
  }
  return true;
}

bool is_feature_ref(const std::string& text) {
  // entity "/" feature ["/" sub …]: at least two non-empty segments of atom characters.
  std::size_t segments = 0;
  std::size_t length = 0;
  for (const char c : text) {
    if (c == '/') {
      if (length == 0) {
        return false;
      }
      ++segments;
      length = 0;
    } else if (is_atom_char(c)) {
      ++length;
    } else {
      return false;
    }
  }
  return length > 0 && segments >= 1;
}

std::size_t code_points(const std::string& text) {
  std::size_t n = 0;
  for (const char c : text) {
    if ((static_cast<unsigned char>(c) & 0xC0U) != 0x80U) {
      ++n;
    }
  }
  return n;
}

std::string range_text(const ParamSpec& spec) {
  if (spec.min && spec.max) {
    return "in [" + detail::format_number(*spec.min) + ", " + detail::format_number(*spec.max) + "]";
  }
  if (spec.min) {
    return ">= " + detail::format_number(*spec.min);
  }
  if (spec.max) {
    return "<= " + detail::format_number(*spec.max);
  }
  return "";
}

std::string quoted_list(const std::vector<std::string>& values) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += (i == 0 ? "" : ", ");
    out += "\"" + values[i] + "\"";
  }
  return out;
}

void check_numbers(const Json& array, std::size_t count, const std::string& pointer, const std::string& what,
                   std::vector<ModelError>& errors) {
  if (!array.is_array() || array.size() != count) {
    errors.push_back({pointer, "expected " + what + ": an array of " + std::to_string(count) + " numbers, got " +
                                   detail::describe_json(array)});
    return;
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (!array[i].is_number() || !std::isfinite(array[i].get<double>())) {
      errors.push_back(
          {pointer + "/" + std::to_string(i), "expected a finite number, got " + detail::describe_json(array[i])});
    }
  }
}

void check_pose(const Json& value, const std::string& pointer, std::vector<ModelError>& errors) {
  if (!value.is_object()) {
    errors.push_back({pointer,
                      "expected a pose object {\"position_m\": [x,y,z], \"rpy_deg\": [r,p,y]} "
                      "(or \"quaternion_xyzw\" instead of \"rpy_deg\"), got " +
                          detail::describe_json(value)});
    return;
  }
  for (const auto& [key, member] : value.items()) {
    if (key != "position_m" && key != "rpy_deg" && key != "quaternion_xyzw" && key != "frame") {
      errors.push_back({pointer + "/" + escape_pointer_token(key),
                        "unknown pose field; expected position_m, rpy_deg, quaternion_xyzw or frame"});
    }
    (void)member;
  }
  if (!value.contains("position_m")) {
    errors.push_back({pointer, "missing \"position_m\": expected [x, y, z] in metres"});
  } else {
    check_numbers(value["position_m"], 3, pointer + "/position_m", "position in metres", errors);
  }
  const bool has_rpy = value.contains("rpy_deg");
  const bool has_quaternion = value.contains("quaternion_xyzw");
  if (has_rpy == has_quaternion) {
    errors.push_back({pointer,
                      "expected exactly one orientation: \"rpy_deg\" [roll, pitch, yaw] in degrees or "
                      "\"quaternion_xyzw\" [x, y, z, w]"});
  }
  if (has_rpy) {
    check_numbers(value["rpy_deg"], 3, pointer + "/rpy_deg", "roll, pitch, yaw in degrees", errors);
  }
  if (has_quaternion) {
    const Json& q = value["quaternion_xyzw"];
    const std::size_t before = errors.size();
    check_numbers(q, 4, pointer + "/quaternion_xyzw", "a unit quaternion [x, y, z, w]", errors);
    if (errors.size() == before) {
      double norm2 = 0.0;
      for (const auto& c : q) {
        norm2 += c.get<double>() * c.get<double>();
      }
      if (std::abs(std::sqrt(norm2) - 1.0) > 1e-3) {
        errors.push_back({pointer + "/quaternion_xyzw", "expected a unit quaternion (norm 1 within 1e-3), norm is " +
                                                            detail::format_number(std::sqrt(norm2))});
      }
    }
  }
  if (value.contains("frame") && (!value["frame"].is_string() || value["frame"].get<std::string>().empty())) {
    errors.push_back({pointer + "/frame",
                      "expected the name of a frame (non-empty string), got " + detail::describe_json(value["frame"])});
  }
}

}  // namespace

std::string_view to_string(ParamType type) {
  for (const auto& [t, name] : kTypeNames) {
    if (t == type) {
      return name;
    }
  }
  return "unknown";
}

std::optional<ParamType> param_type_from_string(std::string_view name) {
  for (const auto& [t, n] : kTypeNames) {
    if (n == name) {
      return t;
    }
  }
  return std::nullopt;
}

const std::vector<std::string_view>& param_type_names() {
  static const std::vector<std::string_view> kNames = [] {
    std::vector<std::string_view> names;
    for (const auto& entry : kTypeNames) {
      names.push_back(entry.second);
    }
    return names;
  }();
  return kNames;
}

ParamSpec object_id_param(std::string name, std::string description, std::optional<std::string> default_id) {
  ParamSpec spec{std::move(name), ParamType::kObjectId, "", std::nullopt, std::nullopt, std::nullopt, {},
                 std::move(description)};
  if (default_id) spec.default_value = nlohmann::json(*default_id);
  return spec;
}

ParamSpec seconds_param(std::string name, double min_s, double max_s, double default_s, std::string description) {
  return ParamSpec{std::move(name), ParamType::kNumber,        "s", min_s,
                   max_s,           nlohmann::json(default_s), {},  std::move(description)};
}

bool operator==(const ParamSpec& a, const ParamSpec& b) {
  return a.name == b.name && a.type == b.type && a.unit == b.unit && a.min == b.min && a.max == b.max &&
         a.default_value == b.default_value && a.enum_values == b.enum_values && a.description == b.description;
}

std::string describe_expectation(const ParamSpec& spec) {
  std::string out;
  switch (spec.type) {
    case ParamType::kNumber:
    case ParamType::kInteger: {
      out = std::string(to_string(spec.type));
      const std::string range = range_text(spec);
      if (!range.empty()) {
        out += " " + range;
      }
      if (!spec.unit.empty()) {
        out += " " + spec.unit;
      }
      return out;
    }
    case ParamType::kBoolean:
      return "boolean";
    case ParamType::kString:
      out = "string";
      if (spec.min || spec.max) {
        out += " of length " + range_text(spec);
      }
      return out;
    case ParamType::kEnum:
      return "one of " + quoted_list(spec.enum_values);
    case ParamType::kPose:
      return "pose {\"position_m\": [x,y,z], \"rpy_deg\": [r,p,y] | \"quaternion_xyzw\": [x,y,z,w], \"frame\"?}";
    case ParamType::kFeatureRef:
      return "feature reference \"entity/feature\" (e.g. \"load/grasp_side\")";
    case ParamType::kObjectId:
      return "object id (1-64 of A-Z a-z 0-9 _ . -, e.g. \"load\")";
    case ParamType::kNumberList: {
      ParamSpec each = spec;
      each.type = ParamType::kNumber;
      return "array of numbers, each a " + describe_expectation(each);
    }
    case ParamType::kStringList:
      out = "array of strings";
      if (spec.min || spec.max) {
        out += " with item count " + range_text(spec);
      }
      return out;
  }
  return out;
}

std::vector<ModelError> check_value(const ParamSpec& spec, const Json& value, const std::string& pointer,
                                    Json* normalized) {
  std::vector<ModelError> errors;
  const std::string expected = "expected " + describe_expectation(spec);
  auto fail = [&](const std::string& why) { errors.push_back({pointer, why}); };
  auto in_range = [&](double v) { return (!spec.min || v >= *spec.min) && (!spec.max || v <= *spec.max); };

  switch (spec.type) {
    case ParamType::kNumber: {
      double v = 0.0;
      if (value.is_number()) {
        v = value.get<double>();
      } else if (value.is_object() && value.size() == 2 && value.contains("value") && value.contains("unit") &&
                 value["value"].is_number() && value["unit"].is_string()) {
        const auto unit = value["unit"].get<std::string>();
        const auto factor = conversion_factor(unit, spec.unit);
        if (!factor) {
          fail("unit \"" + unit + "\" cannot be converted to \"" + spec.unit + "\"; " + expected);
          break;
        }
        v = value["value"].get<double>() * *factor;
      } else {
        fail(expected + (spec.unit.empty() ? "" : " (a number, or {\"value\": x, \"unit\": \"...\"})") + ", got " +
             detail::describe_json(value));
        break;
      }
      if (!std::isfinite(v)) {
        fail(expected + ", got a non-finite number");
      } else if (!in_range(v)) {
        fail(expected + ", got " + detail::format_number(v) + (spec.unit.empty() ? "" : " " + spec.unit));
      } else if (normalized != nullptr) {
        *normalized = value.is_number() ? value : Json(v);
      }
      break;
    }
    case ParamType::kInteger:
      if (!value.is_number_integer()) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (!in_range(value.is_number_unsigned() ? static_cast<double>(value.get<std::uint64_t>())
                                                      : static_cast<double>(value.get<std::int64_t>()))) {
        fail(expected + ", got " + value.dump());
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kBoolean:
      if (!value.is_boolean()) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kString:
      if (!value.is_string()) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (!in_range(static_cast<double>(code_points(value.get_ref<const std::string&>())))) {
        fail(expected + ", got a string of length " + std::to_string(code_points(value.get_ref<const std::string&>())));
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kEnum: {
      bool found = false;
      if (value.is_string()) {
        for (const auto& allowed : spec.enum_values) {
          found = found || allowed == value.get_ref<const std::string&>();
        }
      }
      if (!found) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    }
    case ParamType::kPose:
      check_pose(value, pointer, errors);
      if (errors.empty() && normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kFeatureRef:
      if (!value.is_string() || !is_feature_ref(value.get_ref<const std::string&>())) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kObjectId:
      if (!value.is_string() || !is_object_id(value.get_ref<const std::string&>())) {
        fail(expected + ", got " + detail::describe_json(value));
      } else if (normalized != nullptr) {
        *normalized = value;
      }
      break;
    case ParamType::kNumberList: {
      if (!value.is_array()) {
        fail(expected + ", got " + detail::describe_json(value));
        break;
      }
      ParamSpec each = spec;
      each.type = ParamType::kNumber;
      Json values = Json::array();
      for (std::size_t i = 0; i < value.size(); ++i) {
        Json v;
        for (auto& e : check_value(each, value[i], pointer + "/" + std::to_string(i), &v)) errors.push_back(std::move(e));
        values.push_back(std::move(v));
      }
      if (errors.empty() && normalized != nullptr) {
        *normalized = std::move(values);
      }
      break;
    }
    case ParamType::kStringList: {
      if (!value.is_array()) {
        fail(expected + ", got " + detail::describe_json(value));
        break;
      }
      for (std::size_t i = 0; i < value.size(); ++i) {
        if (!value[i].is_string()) {
          errors.push_back(
              {pointer + "/" + std::to_string(i), "expected a string, got " + detail::describe_json(value[i])});
        }
      }
      if (!in_range(static_cast<double>(value.size()))) {
        fail(expected + ", got " + std::to_string(value.size()) + " items");
      }
      if (errors.empty() && normalized != nullptr) {
        *normalized = value;
      }
      break;
    }
  }
  return errors;
}

Json to_json(const ParamSpec& spec) {
  Json out = Json::object();
  out["name"] = spec.name;
  out["type"] = std::string(to_string(spec.type));
  if (!spec.unit.empty()) {
    out["unit"] = spec.unit;
  }
  if (spec.min) {
    out["min"] = *spec.min;
  }
  if (spec.max) {
    out["max"] = *spec.max;
  }
  if (spec.default_value) {
    out["default"] = *spec.default_value;
  }
  if (spec.type == ParamType::kEnum) {
    out["values"] = spec.enum_values;
  }
  if (!spec.description.empty()) {
    out["description"] = spec.description;
  }
  return out;
}

Parsed<ParamSpec> parse_param_spec(const Json& json, const std::string& pointer) {
  Parsed<ParamSpec> result;
  auto& errors = result.errors;
  if (!json.is_object()) {
    errors.push_back(
        {pointer, "expected a parameter object {\"name\", \"type\", …}, got " + detail::describe_json(json)});
    return result;
  }
  detail::check_keys(json, pointer, {"name", "type", "unit", "min", "max", "default", "values", "description"}, errors);
  ParamSpec spec;
  detail::read_identifier(json, "name", pointer, detail::IdentifierStyle::kSnake, spec.name, errors);

  if (!json.contains("type")) {
    errors.push_back({pointer, "missing \"type\": expected one of " + detail::join(param_type_names())});
  } else if (const auto type =
                 json["type"].is_string() ? param_type_from_string(json["type"].get<std::string>()) : std::nullopt;
             !type) {
    errors.push_back({pointer + "/type", "expected one of " + detail::join(param_type_names()) + ", got " +
                                             detail::describe_json(json["type"])});
    return result;
  } else {
    spec.type = *type;
  }

  if (json.contains("unit")) {
    if (!json["unit"].is_string()) {
      errors.push_back({pointer + "/unit", "expected an SI unit string, got " + detail::describe_json(json["unit"])});
    } else {
      spec.unit = json["unit"].get<std::string>();
      if (!is_si_unit(spec.unit)) {
        errors.push_back({pointer + "/unit", "unit \"" + spec.unit + "\" is not an SI unit; expected one of " +
                                                 detail::join(si_units(), true)});
      } else if (!spec.unit.empty() && !is_numeric(spec.type)) {
        errors.push_back({pointer + "/unit", "only number, integer and number_list parameters have a unit"});
      }
    }
  }

  for (const char* bound : {"min", "max"}) {
    if (!json.contains(bound)) {
      continue;
    }
    const Json& b = json[bound];
    if (!is_numeric(spec.type) && !is_sized(spec.type)) {
      errors.push_back({pointer + "/" + bound,
                        std::string("\"") + bound + "\" applies to number, integer, number_list, string and string_list only"});
    } else if (!b.is_number() || !std::isfinite(b.get<double>())) {
      errors.push_back({pointer + "/" + bound, "expected a number, got " + detail::describe_json(b)});
    } else if (is_sized(spec.type) && (b.get<double>() < 0 || std::floor(b.get<double>()) != b.get<double>())) {
      errors.push_back(
          {pointer + "/" + bound, "expected a non-negative integer (a length or item count), got " + b.dump()});
    } else {
      (std::string(bound) == "min" ? spec.min : spec.max) = b.get<double>();
    }
  }
  if (spec.min && spec.max && *spec.min > *spec.max) {
    errors.push_back({pointer + "/max", "expected max >= min (" + detail::format_number(*spec.min) + "), got " +
                                            detail::format_number(*spec.max)});
  }

  if (spec.type == ParamType::kEnum) {
    const Json* values = json.contains("values") ? &json["values"] : nullptr;
    if (values == nullptr || !values->is_array() || values->empty()) {
      errors.push_back({pointer + (values == nullptr ? "" : "/values"),
                        "an enum parameter needs \"values\": a non-empty array of strings"});
    } else {
      std::set<std::string> seen;
      for (std::size_t i = 0; i < values->size(); ++i) {
        const Json& v = (*values)[i];
        if (!v.is_string() || v.get<std::string>().empty()) {
          errors.push_back({pointer + "/values/" + std::to_string(i),
                            "expected a non-empty string, got " + detail::describe_json(v)});
        } else if (!seen.insert(v.get<std::string>()).second) {
          errors.push_back({pointer + "/values/" + std::to_string(i), "duplicate enum value " + v.dump()});
        } else {
          spec.enum_values.push_back(v.get<std::string>());
        }
      }
    }
  } else if (json.contains("values")) {
    errors.push_back({pointer + "/values", "\"values\" applies to enum parameters only"});
  }

  if (json.contains("description")) {
    if (json["description"].is_string()) {
      spec.description = json["description"].get<std::string>();
    } else {
      errors.push_back(
          {pointer + "/description", "expected a string, got " + detail::describe_json(json["description"])});
    }
  }

  if (json.contains("default") && errors.empty()) {
    Json normalized;
    auto default_errors = check_value(spec, json["default"], pointer + "/default", &normalized);
    if (default_errors.empty()) {
      spec.default_value = std::move(normalized);
    } else {
      for (auto& e : default_errors) {
        e.message = "default value does not satisfy its own declaration: " + e.message;
        errors.push_back(std::move(e));
      }
    }
  }

  if (errors.empty()) {
    result.value = std::move(spec);
  }
  return result;
}

}  // namespace rigger::skill
