#pragma once
/// @file
/// The skill catalog: every skill, monitor and condition built into rigger, from their own
/// descriptions (the skill executor's registry, the monitor host's monitors, the controller's
/// conditions). Two renderings are checked in and kept current by a unit test:
///  - recipes/examples/skill_library.json, the library recipes are validated against offline;
///  - docs/skill-reference.md, the reference for recipe authors.
/// `tools/update-skill-library` regenerates both.

#include <string>

#include <nlohmann/json.hpp>

namespace rigger::catalog {

/// `{ "library_version": 1, "description", "skills": [skills by name, then monitors, then conditions] }`.
nlohmann::json library_json();

/// The Markdown reference of `library` (a document of library_json()'s form).
std::string reference_markdown(const nlohmann::json& library);

}  // namespace rigger::catalog
