#pragma once
// Helpers shared by the recipe tests: the example skill library and error matching.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "recipe/recipe_validator.hpp"

namespace rigger::recipe::testing {

inline std::string source_path(const std::string& relative) { return std::string(RIGGER_SOURCE_DIR) + "/" + relative; }

inline const skill::SkillLibrary& example_library() {
  static const skill::SkillLibrary kLibrary =
      skill::SkillLibrary::load_file(source_path("recipes/examples/skill_library.json"));
  return kLibrary;
}

inline bool has_error(const std::vector<Error>& errors, const std::string& pointer, const std::string& fragment) {
  for (const auto& e : errors) {
    if (e.pointer == pointer && e.message.find(fragment) != std::string::npos) {
      return true;
    }
  }
  return false;
}

/// A minimal valid recipe around `root` (a JSON object text).
inline std::string recipe_with_root(const std::string& root) {
  return R"({"recipe_version": 1, "task_id": "t", "root": )" + root + "}";
}

}  // namespace rigger::recipe::testing
