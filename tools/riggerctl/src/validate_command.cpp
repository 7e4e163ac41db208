// riggerctl validate: a recipe checked offline against a skill-library file.
#include <cstdio>
#include <utility>

#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/skill/skill_library.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {

int validate(const std::string& file, const std::string& library_file) {
  skill::SkillLibrary library;
  try {
    library = skill::SkillLibrary::load_file(library_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "riggerctl: skill library %s: %s\n", library_file.c_str(), e.what());
    return 2;
  }
  recipe::RecipeValidator validator(std::move(library));
  const auto result = validator.validate_file(file);
  if (result.ok()) {
    std::printf("%s: valid (%zu nodes)\n", file.c_str(), result.recipe->tree.nodes.size());
    return 0;
  }
  for (const auto& e : result.errors)
    std::printf("%s: %s: %s\n", file.c_str(), e.pointer.empty() ? "(document)" : e.pointer.c_str(), e.message.c_str());
  return 1;
}

}  // namespace rigger::ctl::tasks
