// The checked-in skill library and skill reference are what the code describes. When this fails, run
// tools/update-skill-library and commit the result.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "catalog.hpp"

namespace rigger::catalog {
namespace {

std::string read(const std::string& relative) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/" + relative);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SkillCatalog, HasThePapersLibrary) {
  const auto library = library_json();
  std::set<std::string> names;
  for (const auto& s : library.at("skills")) names.insert(s.at("name").get<std::string>());
  for (const char* name : {"Localize", "Pick", "Place", "AttachRobotToLoad", "CollaborativeMoveLoad",
                           "InsertVisuallyGuided", "Screw", "TimerMonitor", "ForceMonitor", "YankMonitor",
                           "ObjectLocalized"})
    EXPECT_EQ(names.count(name), 1U) << name;
}

TEST(SkillCatalog, CheckedInLibraryIsCurrent) {
  const auto checked_in = nlohmann::json::parse(read("recipes/examples/skill_library.json"), nullptr, false);
  ASSERT_FALSE(checked_in.is_discarded()) << "recipes/examples/skill_library.json is not JSON";
  EXPECT_EQ(checked_in, library_json()) << "recipes/examples/skill_library.json is out of date: run "
                                           "tools/update-skill-library";
}

TEST(SkillCatalog, CheckedInReferenceIsCurrent) {
  EXPECT_EQ(read("docs/skill-reference.md"), reference_markdown(library_json()))
      << "docs/skill-reference.md is out of date: run tools/update-skill-library";
}

}  // namespace
}  // namespace rigger::catalog
