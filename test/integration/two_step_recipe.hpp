#pragma once
/// @file
/// The integration tests' smallest real recipe: Sequence "find both" of Localize(load), Localize(target)
/// (a scripted executor offering Localize runs it).
#include <string>

#include <nlohmann/json.hpp>

namespace rigger::testing {

inline nlohmann::json two_step(const std::string& task_id) {
  return {
      {"recipe_version", 1},
      {"task_id", task_id},
      {"root",
       {{"type", "Sequence"},
        {"name", "find both"},
        {"children",
         {{{"type", "Skill"}, {"name", "find load"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
          {{"type", "Skill"}, {"name", "find target"}, {"skill", "Localize"}, {"params", {{"object", "target"}}}}}}}}};
}

}  // namespace rigger::testing
