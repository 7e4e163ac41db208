#include "rigger/base/bounded_json.hpp"

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace rigger {
namespace {

TEST(BoundedJson, ParsesOrdinaryDocument) {
  const auto result = parse_json_bounded(R"({"a": [1, 2.5, "x", true, null], "b": {"c": -3}})");
  ASSERT_TRUE(result.ok()) << result.error->to_string();
  EXPECT_EQ(result.value["a"][1], 2.5);
  EXPECT_EQ(result.value["b"]["c"], -3);
  EXPECT_EQ(result.value["a"].size(), 5U);
}

TEST(BoundedJson, ParsesScalarTopLevel) {
  const auto result = parse_json_bounded("  42 ");
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.value, 42);
}

TEST(BoundedJson, AcceptsDepthAtTheLimitAndRefusesOneMore) {
  JsonLimits limits;
  limits.max_depth = 5;
  EXPECT_TRUE(parse_json_bounded("[[[[[1]]]]]", limits).ok());
  const auto result = parse_json_bounded("[[[[[[1]]]]]]", limits);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->offset, 5U);
  EXPECT_EQ(result.error->column, 6U);
  EXPECT_NE(result.error->message.find("at most 5"), std::string::npos) << result.error->message;
}

TEST(BoundedJson, DepthErrorNamesPointerOfEnclosingValue) {
  JsonLimits limits;
  limits.max_depth = 2;
  const auto result = parse_json_bounded(R"({"a": {"b": [1]}})", limits);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->pointer, "/a");
  EXPECT_EQ(result.error->offset, 12U);
}

TEST(BoundedJson, RefusesMillionDeepNestingQuicklyWithoutRecursion) {
  const std::string hostile(1'000'000, '[');
  JsonLimits limits;
  limits.max_bytes = 2'000'000;
  const auto start = std::chrono::steady_clock::now();
  const auto result = parse_json_bounded(hostile, limits);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->offset, limits.max_depth);
  // Generous bound: the point is that it stops at the limit instead of walking a million levels.
  EXPECT_LT(elapsed, std::chrono::seconds(2));
}

TEST(BoundedJson, DepthCountsBracketsInsideStringsAsText) {
  JsonLimits limits;
  limits.max_depth = 2;
  const auto result = parse_json_bounded(R"({"s": "[[[[{{{{", "t": [[1]]})", limits);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->offset, 24U);  // the second '[' of "t"
}

TEST(BoundedJson, RefusesOversizeInputBeforeParsing) {
  JsonLimits limits;
  limits.max_bytes = 100;
  const std::string text = "[" + std::string(200, ' ') + "]";
  const auto result = parse_json_bounded(text, limits);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error->message.find("at most 100 bytes"), std::string::npos);
}

TEST(BoundedJson, Refuses100MegabytesBeforeParsing) {
  // Whitespace only: a parser that started would report a syntax error at the end, not the size.
  const std::string huge(100U * 1024U * 1024U, ' ');
  const auto result = parse_json_bounded(huge);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error->message.find("at most"), std::string::npos) << result.error->message;
  EXPECT_LE(result.error->offset, JsonLimits{}.max_bytes);  // it stopped at the limit, not at 100 MB
}

TEST(BoundedJson, RefusesInvalidUtf8WithPosition) {
  const std::string text = "{\"name\": \"ab\xC3\x28\"}";
  const auto result = parse_json_bounded(text);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error->message.find("UTF-8"), std::string::npos) << result.error->message;
  EXPECT_GE(result.error->offset, 10U);
  EXPECT_LE(result.error->offset, 13U);
  EXPECT_EQ(result.error->line, 1U);
}

TEST(BoundedJson, RefusesRawNonAsciiOutsideStrings) {
  const auto result = parse_json_bounded("[1, \xFF]");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->offset, 4U);
}

TEST(BoundedJson, AcceptsValidMultibyteUtf8) {
  const auto result = parse_json_bounded("{\"name\": \"Kraan \xC3\xA4\xE2\x82\xAC\xF0\x9F\x98\x80\"}");
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.value["name"].get<std::string>().size(), 15U);
}

TEST(BoundedJson, SyntaxErrorReportsLineAndColumn) {
  const auto result = parse_json_bounded("{\n  \"a\": 1,\n  \"b\": tru\n}");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->line, 3U);
  EXPECT_GE(result.error->column, 8U);
  EXPECT_NE(result.error->to_string().find("3:"), std::string::npos);
}

TEST(BoundedJson, RefusesTrailingContent) {
  EXPECT_FALSE(parse_json_bounded("{} {}").ok());
  EXPECT_FALSE(parse_json_bounded("").ok());
}

TEST(BoundedJson, RefusesDuplicateKeysWithPointer) {
  const auto result = parse_json_bounded(R"({"root": {"params": {"x": 1}, "params": {"x": 2}}})");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->pointer, "/root/params");
  EXPECT_NE(result.error->message.find("duplicate key"), std::string::npos);
}

TEST(BoundedJson, PointerTokensAreEscaped) {
  EXPECT_EQ(escape_pointer_token("a/b~c"), "a~1b~0c");
  const auto result = parse_json_bounded(R"({"a/b": [{"k": 1, "k": 2}]})");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error->pointer, "/a~1b/0/k");
}

TEST(BoundedJson, FileErrorsNameTheFile) {
  const auto missing = parse_json_file_bounded("/nonexistent/rigger/file.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error->to_string().find("/nonexistent/rigger/file.json"), std::string::npos);

  const auto path =
      std::filesystem::temp_directory_path() / ("rigger_bounded_json_test-" + std::to_string(getpid()) + ".json");
  {
    std::ofstream out(path);
    out << "{\"a\": [1, 2,]}";
  }
  const auto bad = parse_json_file_bounded(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error->source, path.string());
  JsonLimits tiny;
  tiny.max_bytes = 4;
  const auto big = parse_json_file_bounded(path, tiny);
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.error->message.find("at most 4 bytes"), std::string::npos);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rigger
