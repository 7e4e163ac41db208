#pragma once
/// The declaration of one parameter of a skill, monitor or condition.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/model_error.hpp"

namespace rigger::skill {

/// What a parameter's JSON value must look like.
enum class ParamType {
  kNumber,      ///< a JSON number, or a quantity {"value": x, "unit": "ms"} converted to `unit`
  kInteger,     ///< a JSON integer (no fraction, no exponent form producing a float)
  kBoolean,     ///< true or false
  kString,      ///< any string; min/max bound its length in code points
  kEnum,        ///< one of `enum_values`
  kPose,        ///< {"position_m": [x,y,z], "rpy_deg": [r,p,y] | "quaternion_xyzw": [x,y,z,w], "frame": "world"}
  kFeatureRef,  ///< "entity/feature[/sub…]" naming a world-model feature, e.g. "load/grasp_side"
  kStringList,  ///< an array of strings; min/max bound the number of items
  kObjectId,    ///< a world-model object's id ("load", "target"): 1-64 of [A-Za-z0-9_.-], as the cell file's ids
  kNumberList,  ///< an array of numbers (each as kNumber, in `unit`); min/max bound each value
};

/// "number", "integer", "boolean", "string", "enum", "pose", "feature_ref", "string_list", "object_id",
/// "number_list".
std::string_view to_string(ParamType type);
/// Inverse of to_string(ParamType); std::nullopt for an unknown name.
std::optional<ParamType> param_type_from_string(std::string_view name);
/// Every type name, for error messages.
const std::vector<std::string_view>& param_type_names();

/// One parameter. A parameter without a default is required.
struct ParamSpec {
  std::string name;  ///< [a-z][a-z0-9_]*, units in the name when it has one (max_force_n)
  ParamType type = ParamType::kNumber;
  std::string unit;           ///< SI unit of number/integer/number_list values ("" = dimensionless); see units.hpp
  /// Inclusive lower bound: value (number, integer, each of a number_list), length (string), count (string_list).
  std::optional<double> min;
  std::optional<double> max;  ///< inclusive upper bound, same meaning as `min`
  std::optional<nlohmann::json> default_value;  ///< absent ⇒ the parameter is required
  std::vector<std::string> enum_values;         ///< the allowed strings when type == kEnum
  std::string description;                      ///< for people (UIs, riggerctl skills)

  bool required() const { return !default_value.has_value(); }
  friend bool operator==(const ParamSpec& a, const ParamSpec& b);
};

/// A world-model object id (type object_id): `load`, `target`, … Required when `default_id` is empty.
ParamSpec object_id_param(std::string name, std::string description, std::optional<std::string> default_id = {});

/// A duration in seconds in [min_s, max_s], `default_s` when not given.
ParamSpec seconds_param(std::string name, double min_s, double max_s, double default_s, std::string description);

/// The JSON form: {"name", "type", "unit"?, "min"?, "max"?, "default"?, "values"? (enum), "description"?}.
nlohmann::json to_json(const ParamSpec& spec);

/// Parses one parameter declaration; `pointer` prefixes error pointers. Checks the declaration is
/// coherent (known type, SI unit, min ≤ max, enum values present and unique, default valid).
Parsed<ParamSpec> parse_param_spec(const nlohmann::json& json, const std::string& pointer);

/// Checks one value against `spec`. On success returns no errors and, when `normalized` is not
/// null, stores the value in canonical form there (quantities converted to the SI unit).
/// `pointer` names the value in the caller's document. Never throws.
std::vector<ModelError> check_value(const ParamSpec& spec, const nlohmann::json& value, const std::string& pointer,
                                    nlohmann::json* normalized);

/// Human-readable expectation for `spec`, e.g. "number in [1, 10000] N/s" — used in error messages.
std::string describe_expectation(const ParamSpec& spec);

}  // namespace rigger::skill
