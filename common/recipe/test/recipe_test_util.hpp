#pragma once
// Helpers shared by the recipe tests: the example skill library and error matching.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/recipe/recipe_validator.hpp"

namespace rigger::recipe::testing {

inline std::string source_path(const std::string& relative) { return std::string(RIGGER_SOURCE_DIR) + "/" + relative; }

/// The fixed library the controller's tests are written against (test/data/scripted_skill_library.json,
/// also what the scripted executor announces): the tests check tree semantics, not the real skills.
inline const skill::SkillLibrary& example_library() {
  static const skill::SkillLibrary kLibrary =
      skill::SkillLibrary::load_file(source_path("test/data/scripted_skill_library.json"));
  return kLibrary;
}

/// The real library, generated from the code's descriptions (tools/update-skill-library).
inline const skill::SkillLibrary& generated_library() {
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
