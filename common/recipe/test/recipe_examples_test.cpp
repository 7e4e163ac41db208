// Every recipe in recipes/examples and the paper's recipes/crane_insert.json validates against the generated
// recipes/examples/skill_library.json, and runs to SUCCEEDED in the engine when every leaf succeeds and the operator picks the first option.

#include <filesystem>

#include <gtest/gtest.h>

#include "rigger/bt/engine.hpp"
#include "fake_port.hpp"
#include "recipe_test_util.hpp"

namespace rigger::recipe {
namespace {

std::vector<std::filesystem::path> example_recipes() {
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(testing::source_path("recipes/examples"))) {
    if (entry.path().extension() == ".json" && entry.path().filename() != "skill_library.json") {
      out.push_back(entry.path());
    }
  }
  out.push_back(testing::source_path("recipes/crane_insert.json"));  // the paper's task
  std::sort(out.begin(), out.end());
  return out;
}

TEST(RecipeExamples, ThereAreExamples) { EXPECT_GE(example_recipes().size(), 3U); }

TEST(RecipeExamples, LibraryDescribesThePapersSkills) {
  const auto& lib = testing::generated_library();
  for (const char* name : {"Localize", "Pick", "Place", "AttachRobotToLoad", "CollaborativeMoveLoad",
                           "InsertVisuallyGuided", "Screw"}) {
    ASSERT_NE(lib.find(name), nullptr) << name;
    EXPECT_EQ(lib.find(name)->kind, skill::SkillKind::kSkill) << name;
  }
  for (const char* name : {"TimerMonitor", "ForceMonitor", "YankMonitor"}) {
    ASSERT_NE(lib.find(name), nullptr) << name;
    EXPECT_EQ(lib.find(name)->kind, skill::SkillKind::kMonitor) << name;
  }
  ASSERT_NE(lib.find("ObjectLocalized"), nullptr);
  EXPECT_EQ(lib.find("ObjectLocalized")->kind, skill::SkillKind::kCondition);
}

TEST(RecipeExamples, EveryExampleValidates) {
  const RecipeValidator validator(testing::generated_library());
  for (const auto& path : example_recipes()) {
    const auto result = validator.validate_file(path);
    EXPECT_TRUE(result.ok()) << path << ":\n" << format_errors(result.errors);
  }
}

TEST(RecipeExamples, EveryExampleRunsToSuccessInTheEngine) {
  const RecipeValidator validator(testing::generated_library());
  for (const auto& path : example_recipes()) {
    auto result = validator.validate_file(path);
    ASSERT_TRUE(result.ok()) << path;
    bt::testing::Harness h(result.recipe->tree);
    h.engine->start();
    // Drive: every skill and condition succeeds; monitors stay quiet until shut down; the
    // operator picks option 0.
    for (int step = 0; step < 10'000 && !h.port.result(); ++step) {
      bool acted = false;
      for (bt::NodeIndex i = 0; i < h.engine->spec().nodes.size() && !acted; ++i) {
        const auto& node = h.engine->spec().nodes[i];
        const auto& status = h.engine->status(i);
        if (status.state == bt::NodeState::kStopping) {
          acted = h.stopped(node.id).acted_on();
        } else if (status.state == bt::NodeState::kRunning) {
          if (node.kind == bt::NodeKind::kSkill) {
            acted = h.succeed(node.id).acted_on();
          } else if (node.kind == bt::NodeKind::kCondition) {
            acted = h.condition(node.id, true).acted_on();
          } else if (node.kind == bt::NodeKind::kOperatorDecision) {
            acted = h.decide(node.id, 0).acted_on();
          }
        }
      }
      ASSERT_TRUE(acted) << path << ": nothing to drive but the task is not finished";
    }
    ASSERT_TRUE(h.port.result()) << path;
    EXPECT_EQ(h.port.result()->outcome, bt::TaskOutcome::kSucceeded) << path << ": " << h.port.result()->message;
  }
}

// The paper's attach step (recipes/examples/attach_load.json; the whole task, recipes/crane_insert.json,
// needs the skill executor's library and is validated by the scenario test).
TEST(RecipeExamples, AttachLoadMatchesThePaper) {
  const RecipeValidator validator(testing::generated_library());
  const auto result = validator.validate_file(testing::source_path("recipes/examples/attach_load.json"));
  ASSERT_TRUE(result.ok()) << format_errors(result.errors);
  const auto& tree = result.recipe->tree;
  // The attach step is a Parallel(M=1, K=1) of AttachRobotToLoad and YankMonitor.
  bool found = false;
  for (const auto& node : tree.nodes) {
    if (node.kind == bt::NodeKind::kParallel && node.name == "attach with yank monitor") {
      found = true;
      EXPECT_EQ(node.success_threshold, 1U);
      EXPECT_EQ(node.failure_threshold, 1U);
      ASSERT_EQ(node.children.size(), 2U);
      EXPECT_EQ(tree.nodes[node.children[0]].leaf, "AttachRobotToLoad");
      EXPECT_EQ(tree.nodes[node.children[1]].leaf, "YankMonitor");
    }
  }
  EXPECT_TRUE(found);
  EXPECT_EQ(result.recipe->resources, (std::vector<std::string>{"camera", "gripper", "load", "robot"}));
}

}  // namespace
}  // namespace rigger::recipe
