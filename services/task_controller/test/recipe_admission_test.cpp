// Recipe admission: the typed decision (admit, wait for an executor, reject with a RejectCode).

#include "recipe_admission.hpp"

#include <gtest/gtest.h>

#include "unit_test_util.hpp"

namespace rigger::task_controller {
namespace {

using testing::library_with;

const char* const kPickLoad = R"({"recipe_version": 1, "task_id": "t1", "root":
  {"type": "Skill", "skill": "Pick", "params": {"object": "load", "grasp": "load/grasp_side"}}})";
const char* const kLocalizeLoad = R"({"recipe_version": 1, "task_id": "t1", "root":
  {"type": "Skill", "skill": "Localize", "params": {"object": "load"}}})";

recipe::RecipeValidator validator_with(const std::vector<std::string>& skills) {
  return recipe::RecipeValidator(skill::SkillLibrary::from_json(library_with(skills)));
}

AdmissionRequest request(const std::string& task_id, const char* text, bool may_wait = true) {
  AdmissionRequest r;
  r.task_id = task_id;
  r.text = text;
  r.may_wait = may_wait;
  return r;
}

TEST(RecipeAdmission, AdmitsAValidRecipe) {
  const auto a = admit(request("t1", kLocalizeLoad), validator_with({"Localize"}));
  ASSERT_EQ(a.outcome, Admission::Outcome::kAdmitted) << a.message;
  ASSERT_TRUE(a.recipe);
  EXPECT_EQ(a.recipe->task_id, "t1");
}

TEST(RecipeAdmission, RejectCodesAreTheWireCodes) {
  EXPECT_STREQ(to_string(RejectCode::kInvalidRecipe), "INVALID_RECIPE");
  EXPECT_STREQ(to_string(RejectCode::kDuplicateTask), "DUPLICATE_TASK");
  EXPECT_STREQ(to_string(RejectCode::kResourceConflict), "RESOURCE_CONFLICT");
  EXPECT_STREQ(to_string(RejectCode::kJournalError), "JOURNAL_ERROR");
}

TEST(RecipeAdmission, AnEmptyTaskIdIsInvalid) {
  const auto a = admit(request("", kPickLoad), validator_with({"Pick"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.code, RejectCode::kInvalidRecipe);
  EXPECT_NE(a.message.find("empty task_id"), std::string::npos) << a.message;
}

TEST(RecipeAdmission, AUsedIdIsADuplicateEvenWhenTheRecipeIsBad) {
  auto r = request("t1", "{not json");
  r.id_used = true;
  const auto a = admit(r, validator_with({"Pick"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.code, RejectCode::kDuplicateTask);
  EXPECT_NE(a.message.find("task id t1 was already used"), std::string::npos) << a.message;
}

TEST(RecipeAdmission, OnlyUnknownSkillsWaitForAnExecutorWhenAllowed) {
  const auto wait = admit(request("t1", kPickLoad, true), validator_with({"Localize"}));
  EXPECT_EQ(wait.outcome, Admission::Outcome::kWait);
  EXPECT_NE(wait.message.find("unknown skill \"Pick\""), std::string::npos) << wait.message;
  const auto late = admit(request("t1", kPickLoad, false), validator_with({"Localize"}));
  EXPECT_EQ(late.outcome, Admission::Outcome::kRejected) << "the wait ran out";
  EXPECT_EQ(late.code, RejectCode::kInvalidRecipe);
  ASSERT_EQ(late.errors.size(), 1U);
  EXPECT_EQ(late.error_codes, std::vector<recipe::ErrorCode>{recipe::ErrorCode::kUnknownSkill});
  EXPECT_EQ(late.message.rfind("1 error(s); first: /root/skill: unknown skill", 0), 0U) << late.message;
}

TEST(RecipeAdmission, AnUnknownSkillNextToAnotherErrorDoesNotWait) {
  const char* text = R"({"recipe_version": 1, "task_id": "t1", "root": {"type": "Sequence", "children": [
    {"type": "Skill", "skill": "Pick", "params": {"object": "load", "grasp": "load/grasp_side"}},
    {"type": "Skill", "skill": "Localize", "params": {"object": "load", "min_quality": "high"}}]}})";
  const auto a = admit(request("t1", text, true), validator_with({"Localize"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.code, RejectCode::kInvalidRecipe);
  ASSERT_EQ(a.errors.size(), 2U);
  EXPECT_EQ(a.error_codes,
            (std::vector<recipe::ErrorCode>{recipe::ErrorCode::kUnknownSkill, recipe::ErrorCode::kInvalid}));
}

TEST(RecipeAdmission, AnUnknownConditionDoesNotWait) {
  // No executor brings a condition: the controller answers them itself.
  const char* text = R"({"recipe_version": 1, "task_id": "t1", "root":
    {"type": "Condition", "condition": "Nope"}})";
  const auto a = admit(request("t1", text, true), validator_with({"Localize"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.error_codes, std::vector<recipe::ErrorCode>{recipe::ErrorCode::kUnknownCondition});
}

TEST(RecipeAdmission, TheRecipesTaskIdMustBeTheSamplesOne) {
  const auto a = admit(request("t2", kLocalizeLoad), validator_with({"Localize"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.code, RejectCode::kInvalidRecipe);
  ASSERT_EQ(a.errors.size(), 1U);
  EXPECT_EQ(a.errors[0].pointer, "/task_id");
}

TEST(RecipeAdmission, AResourceHeldByARunningTaskIsAConflict) {
  const std::vector<std::string> camera = {"camera"};
  const std::vector<std::string> other = {"crane", "robot"};
  auto r = request("t1", kLocalizeLoad);
  r.running = {{"a", &other}, {"b", &camera}};
  const auto a = admit(r, validator_with({"Localize"}));
  EXPECT_EQ(a.outcome, Admission::Outcome::kRejected);
  EXPECT_EQ(a.code, RejectCode::kResourceConflict);
  EXPECT_EQ(a.message, "resource camera is claimed by running task b; wait for it or cancel it");
  r.running = {{"a", &other}};
  EXPECT_EQ(admit(r, validator_with({"Localize"})).outcome, Admission::Outcome::kAdmitted);
}

TEST(RecipeAdmission, BadTextIsRejectedNeverThrown) {
  for (const char* text : {"", "{", "[]", "null", "{\"recipe_version\": 1}"}) {
    const auto a = admit(request("t1", text), validator_with({"Pick"}));
    EXPECT_EQ(a.outcome, Admission::Outcome::kRejected) << text;
    EXPECT_EQ(a.code, RejectCode::kInvalidRecipe) << text;
    EXPECT_FALSE(a.errors.empty()) << text;
  }
}

}  // namespace
}  // namespace rigger::task_controller
