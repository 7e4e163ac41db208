// Hostile and malformed recipe text is refused at the parser, fast, with a position.

#include <chrono>
#include <string>

#include <gtest/gtest.h>

#include "recipe_test_util.hpp"

namespace rigger::recipe {
namespace {

using testing::example_library;

TEST(RecipeParse, MillionDeepNestingIsRefusedFast) {
  const RecipeValidator validator(example_library());
  std::string hostile(1'000'000, '[');
  hostile += std::string(1'000'000, ']');
  const auto start = std::chrono::steady_clock::now();
  const auto result = validator.validate_text(hostile);
  ASSERT_FALSE(result.ok());
  ASSERT_EQ(result.errors.size(), 1U);
  // 2 MB is within the default size bound, so the depth bound is what refuses it.
  EXPECT_NE(result.errors[0].message.find("nesting deeper than 128"), std::string::npos) << result.errors[0].message;
  EXPECT_NE(result.errors[0].message.find("line 1, column 129:"), std::string::npos) << result.errors[0].message;
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST(RecipeParse, DeepNestingInsideAValidLookingRecipeIsRefused) {
  const RecipeValidator validator(example_library());
  std::string root;
  for (int i = 0; i < 200; ++i) {
    root += R"({"type": "Inverter", "child": )";
  }
  root += R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}})";
  root += std::string(200, '}');
  const auto result = validator.validate_text(testing::recipe_with_root(root));
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("nesting deeper"), std::string::npos);
  EXPECT_EQ(result.errors[0].pointer.rfind("/root/child/child", 0), 0U) << result.errors[0].pointer;
}

TEST(RecipeParse, DeepestAdmittedRecipeValidates) {
  // Decorators cost one JSON level each and come late in the schema's if/else chain: the worst
  // case for the schema validator's recursion that the depth bound still admits.
  const RecipeValidator validator(example_library());
  for (const char* decorator : {"ForceSuccess", "Inverter"}) {
    std::string root;
    const int levels = 125;  // document object, "root", 125 decorators, the leaf and its params: 128
    for (int i = 0; i < levels; ++i) {
      root += std::string(R"({"type": ")") + decorator + R"(", "child": )";
    }
    root += R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}})";
    root += std::string(levels, '}');
    const auto result = validator.validate_text(testing::recipe_with_root(root));
    ASSERT_TRUE(result.ok()) << decorator << ": " << format_errors(result.errors);
    EXPECT_EQ(result.recipe->tree.nodes.size(), 126U);
  }
}

TEST(RecipeParse, HundredMegabytesRefusedBeforeParsing) {
  const RecipeValidator validator(example_library());
  std::string huge = testing::recipe_with_root(R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}})");
  huge += std::string(100U * 1024U * 1024U, ' ');
  const auto start = std::chrono::steady_clock::now();
  const auto result = validator.validate_text(huge);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("expected at most 4194304 bytes"), std::string::npos);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
}

TEST(RecipeParse, InvalidUtf8RefusedWithPosition) {
  const RecipeValidator validator(example_library());
  const std::string text = "{\"recipe_version\": 1,\n \"task_id\": \"t\xFF\", \"root\": {}}";
  const auto result = validator.validate_text(text);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("UTF-8"), std::string::npos) << result.errors[0].message;
  EXPECT_NE(result.errors[0].message.find("line 2, column "), std::string::npos) << result.errors[0].message;
}

TEST(RecipeParse, OverlongUtf8EncodingRefused) {
  const RecipeValidator validator(example_library());
  // "/" encoded in two bytes (0xC0 0xAF) is invalid UTF-8.
  const auto result = validator.validate_text("{\"task_id\": \"a\xC0\xAF\"}");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("UTF-8"), std::string::npos);
}

TEST(RecipeParse, SyntaxErrorsNameLineAndColumn) {
  const RecipeValidator validator(example_library());
  const auto result = validator.validate_text("{\n  \"recipe_version\": 1,\n  \"task_id\": \"t\"\n  \"root\": {}\n}");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.errors[0].message.rfind("line 4, column 3: ", 0), 0U) << result.errors[0].message;
}

TEST(RecipeParse, DuplicateKeysRefusedWithPointer) {
  const RecipeValidator validator(example_library());
  const auto result = validator.validate_text(testing::recipe_with_root(
      R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}, "skill": "Pick"})"));
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.errors[0].pointer, "/root/skill");
}

TEST(RecipeParse, EmptyAndTrailingGarbageRefused) {
  const RecipeValidator validator(example_library());
  EXPECT_FALSE(validator.validate_text("").ok());
  EXPECT_FALSE(validator.validate_text("   ").ok());
  EXPECT_FALSE(validator.validate_text(testing::recipe_with_root(
                                           R"({"type": "Skill", "skill": "Localize", "params": {"object": "x"}})") +
                                       " trailing")
                   .ok());
}

TEST(RecipeParse, ConfigurableLimits) {
  ValidatorOptions options;
  options.limits.max_bytes = 64;
  const RecipeValidator validator(example_library(), options);
  const auto result = validator.validate_text(
      testing::recipe_with_root(R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}})"));
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("at most 64 bytes"), std::string::npos);
}

TEST(RecipeParse, ValidateDocumentBoundsDepthOfInMemoryDocuments) {
  const RecipeValidator validator(example_library());
  nlohmann::json deep = nlohmann::json::array();
  for (int i = 0; i < 500; ++i) {
    deep = nlohmann::json::array({deep});
  }
  const auto result = validator.validate_document(deep);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("nesting deeper"), std::string::npos);
}

TEST(RecipeParse, MissingFileNamesTheFile) {
  const RecipeValidator validator(example_library());
  const auto result = validator.validate_file("/nonexistent/recipe.json");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.errors[0].message.find("/nonexistent/recipe.json"), std::string::npos);
}

}  // namespace
}  // namespace rigger::recipe
