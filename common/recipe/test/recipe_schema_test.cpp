// The published JSON Schema: every error, each with its pointer and what was expected.

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "rigger/recipe/recipe_schema.hpp"
#include "recipe_test_util.hpp"

namespace rigger::recipe {
namespace {

using testing::has_error;

std::vector<Error> schema_errors(const std::string& text) {
  return SchemaValidator::recipe().validate(nlohmann::json::parse(text));
}

std::string dump(const std::vector<Error>& errors) { return format_errors(errors); }

TEST(RecipeSchema, EmbeddedSchemaIsThePublishedFile) {
  std::ifstream in(testing::source_path("recipes/schema/recipe.schema.json"));
  std::stringstream buffer;
  buffer << in.rdbuf();
  EXPECT_EQ(nlohmann::json::parse(buffer.str()), nlohmann::json::parse(recipe_schema_text()));
  EXPECT_EQ(nlohmann::json::parse(recipe_schema_text())["$schema"], "http://json-schema.org/draft-07/schema#");
}

TEST(RecipeSchema, MinimalRecipeIsValid) {
  EXPECT_TRUE(schema_errors(testing::recipe_with_root(R"({"type": "Skill", "skill": "Localize"})")).empty());
}

TEST(RecipeSchema, TopLevelErrorsAllReported) {
  const auto errors = schema_errors(R"({"recipe_version": 2, "task_id": "bad id!", "colour": "red"})");
  EXPECT_TRUE(has_error(errors, "", "missing required property \"root\": expected a node object")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/recipe_version", "expected the value 1, got integer 2")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/task_id", "expected a string matching")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/colour", "unknown property \"colour\"; expected one of")) << dump(errors);
  EXPECT_EQ(errors.size(), 4U) << dump(errors);
}

TEST(RecipeSchema, NonObjectDocument) {
  const auto errors = schema_errors("[1, 2]");
  ASSERT_EQ(errors.size(), 1U) << dump(errors);
  EXPECT_EQ(errors[0].pointer, "");
  EXPECT_NE(errors[0].message.find("expected a recipe object"), std::string::npos);
}

TEST(RecipeSchema, UnknownNodeTypeListsTheTypes) {
  const auto errors = schema_errors(testing::recipe_with_root(R"({"type": "Sequense", "children": []})"));
  ASSERT_EQ(errors.size(), 1U) << dump(errors);
  EXPECT_EQ(errors[0].pointer, "/root/type");
  EXPECT_NE(errors[0].message.find("one of \"Sequence\", \"Fallback\", \"Parallel\""), std::string::npos)
      << errors[0].message;
  EXPECT_NE(errors[0].message.find("got string \"Sequense\""), std::string::npos);
}

TEST(RecipeSchema, WrongTypesDeepInTheTreeEachNamed) {
  const auto errors = schema_errors(testing::recipe_with_root(R"({
    "type": "Sequence", "children": [
      {"type": "Parallel", "success_threshold": "one", "failure_threshold": 0, "children": [
         {"type": "Skill", "skill": "Pick", "params": [1]},
         5 ]},
      {"type": "Timeout", "duration_s": -1, "child": {"type": "Monitor", "monitor": "lowercase"}},
      {"type": "Retry", "child": {"type": "Skill", "skill": "Pick"}},
      {"type": "OperatorDecision", "prompt": "", "options": [{"label": "a"}]}
    ]})"));
  EXPECT_TRUE(has_error(errors, "/root/children/0/success_threshold", "expected an integer >= 1, got string \"one\""))
      << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/0/failure_threshold", "expected an integer >= 1, got integer 0"))
      << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/0/children/0/params", "expected an object, got array of 1 item"))
      << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/0/children/1", "expected a node object")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/1/duration_s", "expected a number > 0 and <= 86400, got integer -1"))
      << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/1/child/monitor", "matching ^[A-Z]")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/2", "missing required property \"max_attempts\": expected an integer"))
      << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/3/prompt", "expected a non-empty string")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/children/3/options/0", "missing required property \"child\"")) << dump(errors);
  // No wrapper noise ("failed to validate item #0", "child schema #3").
  for (const auto& e : errors) {
    EXPECT_EQ(e.message.find("Failed to validate"), std::string::npos) << e.to_string();
  }
}

TEST(RecipeSchema, UnknownPropertyListsThatNodeTypesProperties) {
  const auto errors = schema_errors(testing::recipe_with_root(R"({"type": "Retry", "max_attempts": 2, "times": 3,
      "child": {"type": "Skill", "skill": "Pick"}})"));
  ASSERT_EQ(errors.size(), 1U) << dump(errors);
  EXPECT_EQ(errors[0].pointer, "/root/times");
  EXPECT_NE(errors[0].message.find("\"max_attempts\""), std::string::npos) << errors[0].message;
  EXPECT_NE(errors[0].message.find("\"child\""), std::string::npos);
  EXPECT_EQ(errors[0].message.find("\"children\""), std::string::npos);
}

TEST(RecipeSchema, EmptyChildrenAndMissingChild) {
  const auto errors = schema_errors(testing::recipe_with_root(R"({"type": "Fallback", "children": []})"));
  EXPECT_TRUE(has_error(errors, "/root/children", "expected an array of 1 to 10000 items, got array of 0 items"))
      << dump(errors);
  const auto missing = schema_errors(testing::recipe_with_root(R"({"type": "Inverter"})"));
  EXPECT_TRUE(has_error(missing, "/root", "missing required property \"child\"")) << dump(missing);
}

TEST(RecipeSchema, LeafNeedsItsNameField) {
  const auto errors = schema_errors(testing::recipe_with_root(R"({"type": "Skill", "monitor": "YankMonitor"})"));
  EXPECT_TRUE(has_error(errors, "/root", "missing required property \"skill\"")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/root/monitor", "unknown property \"monitor\"")) << dump(errors);
}

TEST(RecipeSchema, AssumptionsMustBeFacts) {
  const auto errors = schema_errors(R"J({"recipe_version": 1, "task_id": "t", "assumptions": ["ok(a)", "not a fact", 3],
      "root": {"type": "Skill", "skill": "Localize"}})J");
  EXPECT_TRUE(has_error(errors, "/assumptions/1", "expected a string matching")) << dump(errors);
  EXPECT_TRUE(has_error(errors, "/assumptions/2", "got integer 3")) << dump(errors);
  EXPECT_EQ(errors.size(), 2U) << dump(errors);
}

TEST(RecipeSchema, PointerTokensEscaped) {
  const auto errors = schema_errors(R"({"recipe_version": 1, "task_id": "t", "a/b~c": 1,
      "root": {"type": "Skill", "skill": "Localize"}})");
  ASSERT_EQ(errors.size(), 1U) << dump(errors);
  EXPECT_EQ(errors[0].pointer, "/a~1b~0c");
}

TEST(RecipeSchema, BrokenSchemaIsASetupError) {
  EXPECT_THROW(SchemaValidator(nlohmann::json::parse(R"({"type": "object", "properties": {"a": {"$ref": "#/nowhere"}}})")),
               std::runtime_error);
}

}  // namespace
}  // namespace rigger::recipe
