#pragma once
/// @file
/// The conditions the task controller answers itself, from the world model (no executor runs them):
/// their descriptions, as a skill-library document, for the validator, riggerctl and the skill catalog.

#include <nlohmann/json.hpp>

namespace rigger::recipe {

/// `{ "library_version": 1, "skills": [ {"name": "ObjectLocalized", "kind": "condition", …} ] }`.
const nlohmann::json& controller_conditions_json();

}  // namespace rigger::recipe
