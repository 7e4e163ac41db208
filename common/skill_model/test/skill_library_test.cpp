#include "rigger/skill/skill_library.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace rigger::skill {
namespace {

using Json = nlohmann::json;

Json library_json() {
  return Json::parse(R"json({"library_version": 1, "skills": [
    {"name": "Localize", "kind": "skill", "params": [{"name": "object", "type": "string"}],
     "resources": ["camera"], "postconditions": ["localized($object)"]},
    {"name": "YankMonitor", "kind": "monitor",
     "params": [{"name": "max_yank_n_per_s", "type": "number", "unit": "N/s", "min": 1, "default": 400}]},
    {"name": "ObjectLocalized", "kind": "condition", "params": [{"name": "object", "type": "string"}],
     "postconditions": ["localized($object)"]}
  ]})json");
}

TEST(SkillLibrary, ParsesAndFinds) {
  const auto lib = SkillLibrary::from_json(library_json());
  EXPECT_EQ(lib.size(), 3U);
  ASSERT_NE(lib.find("YankMonitor"), nullptr);
  EXPECT_EQ(lib.find("YankMonitor")->kind, SkillKind::kMonitor);
  EXPECT_EQ(lib.find("Nope"), nullptr);
  EXPECT_EQ(lib.names(SkillKind::kSkill), std::vector<std::string>{"Localize"});
  EXPECT_EQ(lib.names(SkillKind::kCondition), std::vector<std::string>{"ObjectLocalized"});
}

TEST(SkillLibrary, JsonRoundTrip) {
  const auto lib = SkillLibrary::from_json(library_json());
  const auto again = SkillLibrary::from_json(lib.to_json());
  EXPECT_EQ(again.to_json(), lib.to_json());
  EXPECT_EQ(again.to_json()["library_version"], kLibraryVersion);
}

TEST(SkillLibrary, FileRoundTrip) {
  const auto path =
      std::filesystem::temp_directory_path() / ("rigger_skill_library_test-" + std::to_string(getpid()) + ".json");
  const auto lib = SkillLibrary::from_json(library_json());
  lib.save_file(path);
  const auto loaded = SkillLibrary::load_file(path);
  EXPECT_EQ(loaded.to_json(), lib.to_json());
  std::filesystem::remove(path);
}

TEST(SkillLibrary, LoadFileErrorsNameFileAndPlace) {
  const auto path =
      std::filesystem::temp_directory_path() / ("rigger_skill_library_bad-" + std::to_string(getpid()) + ".json");
  {
    std::ofstream out(path);
    out << "{\"library_version\": 1, \"skills\": [\n  {\"name\": \"X\", \"kind\": \"skill\",}\n]}";
  }
  try {
    SkillLibrary::load_file(path);
    FAIL() << "expected SkillModelError";
  } catch (const SkillModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string() + ":2:"), std::string::npos) << what;
  }
  {
    std::ofstream out(path);
    out << R"json({"library_version": 1, "skills": [{"name": "X", "kind": "skill", "params": [{"name": "a"}]}]})json";
  }
  try {
    SkillLibrary::load_file(path);
    FAIL() << "expected SkillModelError";
  } catch (const SkillModelError& e) {
    ASSERT_EQ(e.errors().size(), 1U);
    EXPECT_EQ(e.errors()[0].pointer, "/skills/0/params/0");
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos);
  }
  std::filesystem::remove(path);
  EXPECT_THROW(SkillLibrary::load_file(path), SkillModelError);
}

TEST(SkillLibrary, RejectsWrongVersionAndDuplicates) {
  Json j = library_json();
  j["library_version"] = 2;
  j["skills"].push_back(j["skills"][0]);
  j["skills"][3]["kind"] = "condition";
  j["skills"][3].erase("resources");
  const auto parsed = SkillLibrary::parse(j);
  ASSERT_FALSE(parsed.ok());
  ASSERT_EQ(parsed.errors.size(), 2U);
  EXPECT_EQ(parsed.errors[0].pointer, "/library_version");
  EXPECT_EQ(parsed.errors[1].pointer, "/skills/3/name");
  EXPECT_NE(parsed.errors[1].message.find("unique across"), std::string::npos);
}

TEST(SkillLibrary, RejectsMissingSkillsAndNonObject) {
  EXPECT_FALSE(SkillLibrary::parse({{"library_version", 1}}).ok());
  EXPECT_FALSE(SkillLibrary::parse(Json::array()).ok());
  EXPECT_FALSE(SkillLibrary::parse({{"library_version", 1}, {"skills", Json::array()}, {"x", 1}}).ok());
  EXPECT_TRUE(SkillLibrary::parse({{"library_version", 1}, {"skills", Json::array()}}).ok());
}

TEST(SkillLibrary, AddAndMergeDetectConflicts) {
  auto lib = SkillLibrary::from_json(library_json());
  SkillDescription same = *lib.find("Localize");
  EXPECT_TRUE(lib.add(same));
  SkillDescription different = same;
  different.description = "changed";
  EXPECT_FALSE(lib.add(different));
  EXPECT_EQ(lib.find("Localize")->description, "");

  SkillLibrary other;
  other.add(different);
  SkillDescription fresh;
  fresh.name = "Screw";
  other.add(fresh);
  const auto errors = lib.merge(other);
  ASSERT_EQ(errors.size(), 1U);
  EXPECT_NE(errors[0].message.find("Localize"), std::string::npos);
  EXPECT_NE(lib.find("Screw"), nullptr);
}

}  // namespace
}  // namespace rigger::skill
