// Scale: a 10,000-node recipe validates and builds, and a Parallel with 1,000 monitor leaves
// validates and runs. Correctness only; timing belongs to the benchmarks.

#include <gtest/gtest.h>

#include "rigger/bt/engine.hpp"
#include "fake_port.hpp"
#include "recipe_test_util.hpp"
#include "scale_recipes.hpp"

namespace rigger::recipe {
namespace {

using rigger::testing::big_recipe;

TEST(Scale, TenThousandNodeRecipeValidatesAndBuilds) {
  const auto document = big_recipe(1000);
  const std::string text = document.dump();
  const RecipeValidator validator(testing::example_library());
  const auto result = validator.validate_text(text);
  ASSERT_TRUE(result.ok()) << format_errors(result.errors);
  EXPECT_EQ(result.recipe->tree.nodes.size(), 1U + 1000U * 9U);
  bt::testing::FakePort port;
  bt::Engine engine(result.recipe->tree, port);
  EXPECT_EQ(engine.spec().nodes.size(), 9001U);
  ASSERT_TRUE(engine.find("root/999/0/0/3").has_value());
  EXPECT_EQ(engine.spec().nodes[*engine.find("root/999/0/0/3")].leaf, "Place");
}

TEST(Scale, TenThousandNodeRecipeWithOneMistakeReportsIt) {
  auto document = big_recipe(1000);
  document["root"]["children"][777]["child"]["children"][0]["children"][2]["params"]["approach_speed_m_per_s"] = 9;
  const RecipeValidator validator(testing::example_library());
  const auto result = validator.validate_document(document);
  ASSERT_FALSE(result.ok());
  ASSERT_EQ(result.errors.size(), 1U) << format_errors(result.errors);
  EXPECT_EQ(result.errors[0].pointer,
            "/root/children/777/child/children/0/children/2/params/approach_speed_m_per_s");
}

TEST(Scale, ParallelWithThousandMonitorsValidatesAndRuns) {
  using Json = nlohmann::json;
  Json children = Json::array({{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}}});
  for (int i = 0; i < 1000; ++i) {
    children.push_back({{"type", "Monitor"}, {"monitor", i % 2 == 0 ? "YankMonitor" : "TimerMonitor"},
                        {"params", i % 2 == 0 ? Json::object() : Json{{"max_duration_s", 10 + i}}}});
  }
  const Json document = {{"recipe_version", 1},
                         {"task_id", "many-monitors"},
                         {"root", {{"type", "Parallel"}, {"success_threshold", 1}, {"failure_threshold", 1},
                                   {"children", children}}}};
  const RecipeValidator validator(testing::example_library());
  const auto result = validator.validate_document(document);
  ASSERT_TRUE(result.ok()) << format_errors(result.errors);
  bt::testing::Harness h(result.recipe->tree);
  h.engine->start();
  EXPECT_EQ(h.port.starts().size(), 1001U);
  h.fail("root/641", "TOO_LONG");
  EXPECT_EQ(h.port.shutdowns().size(), 1000U);
  h.stop_all_stopping();
  ASSERT_TRUE(h.port.result());
  EXPECT_EQ(h.port.result()->origin, "root/641");
  // With M = 2 the same Parallel is refused: only the Localize can succeed.
  Json too_many = document;
  too_many["root"]["success_threshold"] = 2;
  EXPECT_FALSE(validator.validate_document(too_many).ok());
}

}  // namespace
}  // namespace rigger::recipe
