#pragma once
/// @file
/// The skill executor's public face to other programs (the skill catalog, tools/update-skill-library):
/// the skill-library document of every skill built into it. Everything else of the executor is private.

#include <nlohmann/json.hpp>

namespace rigger::skill_executor {

/// `{ "library_version": 1, "skills": [description…] }` of every built-in skill, sorted by name.
nlohmann::json builtin_skill_library_json();

}  // namespace rigger::skill_executor
