#pragma once
/// Describing JSON values in error messages ("expected …, got string \"abc\"").

#include <string>

#include <nlohmann/json.hpp>

namespace rigger::skill {

/// "5", "0.25", "1e-06": integral values without a fraction, others with up to 10 significant digits.
std::string format_number(double value);

/// A short description of a JSON value for "got …": `string "abc"` (long strings truncated),
/// `integer 5`, `number 0.5`, `boolean true`, `null`, `object`, `array of 3 items`.
std::string describe_json(const nlohmann::json& value);

}  // namespace rigger::skill
