#pragma once
/// @file
/// The skill library recipes are validated against: what the live executors announce, merged as the task
/// controller merges it, plus the conditions the controller answers itself. One function, so that the
/// controller and the console's planner can never disagree about what a recipe may use.

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/skill_library.hpp"

namespace rigger::recipe {

/// An announced library arrives as text over DDS: parsed with bounds (size, depth, duplicate keys).
/// Returns the document, or null with `error` set to where and what.
nlohmann::json parse_announced_library(std::string_view text, std::string* error = nullptr);

/// One live executor's announced library (a parsed document; null when it was not acceptable JSON).
struct AnnouncedLibrary {
  std::string executor_id;
  const nlohmann::json* document = nullptr;
};

/// Every library in `announced` merged in order, then the controller's own conditions unless an executor
/// announces one of them too. A library that is null, invalid or conflicting is left out, with a line in
/// `problems` naming the executor ("executor library invalid executor=<id> errors=<n>", …).
skill::SkillLibrary live_library(const std::vector<AnnouncedLibrary>& announced,
                                 std::vector<std::string>* problems = nullptr);

}  // namespace rigger::recipe
