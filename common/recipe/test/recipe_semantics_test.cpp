// Semantic checks against the skill library: names, parameters, thresholds, resources,
// reachability and the precondition flow; and the tree the validator builds.

#include <gtest/gtest.h>

#include "recipe_test_util.hpp"

namespace rigger::recipe {
namespace {

using testing::example_library;
using testing::has_error;
using testing::recipe_with_root;

// Leaves of the example library, with valid parameters.
const char* const kLocalizeLoad = R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}})";
const char* const kLocalizeTarget = R"({"type": "Skill", "skill": "Localize", "params": {"object": "target"}})";
const char* const kPickLoad = R"({"type": "Skill", "skill": "Pick", "params": {"object": "load", "grasp": "load/grasp_side"}})";
const char* const kPlaceLoad =
    R"({"type": "Skill", "skill": "Place", "params": {"object": "load", "pose": {"position_m": [0,0,0], "rpy_deg": [0,0,0]}}})";
const char* const kYank = R"({"type": "Monitor", "monitor": "YankMonitor"})";
const char* const kForce = R"({"type": "Monitor", "monitor": "ForceMonitor", "params": {"max_force_n": 100}})";

std::string seq(const std::vector<std::string>& children) {
  std::string out = R"({"type": "Sequence", "children": [)";
  for (std::size_t i = 0; i < children.size(); ++i) {
    out += (i == 0 ? "" : ", ") + children[i];
  }
  return out + "]}";
}

std::string composite(const std::string& type, const std::vector<std::string>& children, const std::string& extra = "") {
  std::string out = seq(children);
  out.replace(out.find("Sequence"), 8, type);
  if (!extra.empty()) {
    out.insert(out.size() - 1, ", " + extra);
  }
  return out;
}

std::string par(std::size_t m, std::size_t k, const std::vector<std::string>& children) {
  return composite("Parallel", children,
                   "\"success_threshold\": " + std::to_string(m) + ", \"failure_threshold\": " + std::to_string(k));
}

ValidationResult validate(const std::string& root, ValidatorOptions options = {}) {
  return RecipeValidator(example_library(), std::move(options)).validate_text(recipe_with_root(root));
}

std::string dump(const ValidationResult& r) { return format_errors(r.errors); }

const bt::NodeSpec& node(const ValidatedRecipe& recipe, const std::string& id) {
  for (const auto& n : recipe.tree.nodes) {
    if (n.id == id) {
      return n;
    }
  }
  throw std::out_of_range(id);
}

// --- The built tree -----------------------------------------------------------------------------

TEST(RecipeTree, IdsPointersAndFieldsOfEveryNodeType) {
  const auto r = RecipeValidator(example_library()).validate_text(R"({
    "recipe_version": 1, "task_id": "all-types", "description": "d", "stop_timeout_s": 7,
    "root": {"type": "Sequence", "name": "top", "children": [
      {"type": "Condition", "condition": "ObjectLocalized", "params": {"object": "load"}},
      {"type": "Retry", "max_attempts": 3, "stop_timeout_s": 2, "child":
        {"type": "Skill", "skill": "Localize", "executor": "perception-1", "params": {"object": "target"}}},
      {"type": "Parallel", "success_threshold": 1, "failure_threshold": 2, "children": [
        {"type": "Timeout", "duration_s": 30, "child": {"type": "Skill", "skill": "Pick",
          "params": {"object": "load", "grasp": "load/grasp_side"}, "stop_timeout_s": 1.5}},
        {"type": "Monitor", "monitor": "YankMonitor", "params": {"max_yank_n_per_s": {"value": 0.5, "unit": "kN/s"}}}]},
      {"type": "Repeat", "repetitions": 2, "child": {"type": "ForceSuccess", "child":
        {"type": "Inverter", "child": {"type": "Monitor", "monitor": "ForceMonitor", "params": {"max_force_n": 90}}}}},
      {"type": "OperatorDecision", "prompt": "Place?", "options": [
        {"label": "yes", "child": {"type": "Skill", "skill": "Place",
          "params": {"object": "load", "pose": {"position_m": [1,2,3], "rpy_deg": [0,0,90]}}}},
        {"label": "no", "child": {"type": "Fallback", "children": [{"type": "Condition", "condition": "ObjectLocalized",
          "params": {"object": "load"}}]}}]}
    ]}})");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& recipe = *r.recipe;
  EXPECT_EQ(recipe.task_id, "all-types");
  EXPECT_EQ(recipe.description, "d");
  EXPECT_EQ(recipe.tree.nodes[recipe.tree.root].id, "root");
  EXPECT_EQ(recipe.tree.nodes.size(), 16U);

  EXPECT_EQ(node(recipe, "root").name, "top");
  EXPECT_EQ(node(recipe, "root").pointer, "/root");
  EXPECT_EQ(node(recipe, "root/0").kind, bt::NodeKind::kCondition);
  EXPECT_EQ(node(recipe, "root/0").params["max_age_s"], 5);  // default filled in
  EXPECT_EQ(node(recipe, "root/1").count, 3U);
  const auto& localize = node(recipe, "root/1/0");
  EXPECT_EQ(localize.pointer, "/root/children/1/child");
  EXPECT_EQ(localize.executor, "perception-1");
  EXPECT_EQ(localize.stop_timeout, bt::Seconds(2.0));  // inherited from the Retry
  EXPECT_EQ(localize.resources, std::vector<std::string>{"camera"});
  EXPECT_EQ(localize.params["timeout_s"], 5);
  EXPECT_EQ(node(recipe, "root/2").success_threshold, 1U);
  EXPECT_EQ(node(recipe, "root/2").failure_threshold, 2U);
  EXPECT_EQ(node(recipe, "root/2/0").duration, bt::Seconds(30.0));
  const auto& pick = node(recipe, "root/2/0/0");
  EXPECT_EQ(pick.stop_timeout, bt::Seconds(1.5));
  EXPECT_EQ(pick.resources, (std::vector<std::string>{"robot", "gripper", "load"}));
  EXPECT_DOUBLE_EQ(node(recipe, "root/2/1").params["max_yank_n_per_s"].get<double>(), 500.0);  // kN/s → N/s
  EXPECT_EQ(node(recipe, "root/2/1").stop_timeout, bt::Seconds(7.0));  // recipe-level default
  EXPECT_EQ(node(recipe, "root/3").count, 2U);
  EXPECT_EQ(node(recipe, "root/3/0/0/0").leaf, "ForceMonitor");
  const auto& decision = node(recipe, "root/4");
  EXPECT_EQ(decision.prompt, "Place?");
  EXPECT_EQ(decision.options, (std::vector<std::string>{"yes", "no"}));
  EXPECT_EQ(node(recipe, "root/4/1/0").pointer, "/root/children/4/options/1/child/children/0");
  EXPECT_EQ(recipe.resources, (std::vector<std::string>{"camera", "gripper", "load", "robot"}));
  EXPECT_NO_THROW(bt::check_tree_spec(recipe.tree));
}

TEST(RecipeTree, RestartableIsASkillsOptionalBooleanDefaultFalse) {
  const auto r =
      RecipeValidator(example_library())
          .validate_text(recipe_with_root(
              seq({R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}, "restartable": true})",
                   kLocalizeTarget})));
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_TRUE(r.recipe->tree.nodes[1].restartable);
  EXPECT_FALSE(r.recipe->tree.nodes[2].restartable);
  const auto bad =
      RecipeValidator(example_library())
          .validate_text(recipe_with_root(
              seq({R"({"type": "Skill", "skill": "Localize", "params": {"object": "load"}, "restartable": "yes"})"})));
  EXPECT_FALSE(bad.ok());
  EXPECT_TRUE(has_error(bad.errors, "/root/children/0/restartable", "")) << dump(bad);
  const auto monitor =
      RecipeValidator(example_library())
          .validate_text(recipe_with_root(R"({"type": "Monitor", "monitor": "YankMonitor", "restartable": true})"));
  EXPECT_FALSE(monitor.ok()) << "monitors always start again: the field is a Skill's";
}

TEST(RecipeTree, DefaultStopTimeoutFromOptions) {
  ValidatorOptions options;
  options.default_stop_timeout = bt::Seconds(4.0);
  const auto r = validate(kLocalizeLoad, options);
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.recipe->tree.nodes[0].stop_timeout, bt::Seconds(4.0));
}

// --- Names and parameters ----------------------------------------------------------------------

TEST(RecipeSemantics, UnknownSkillSuggestsAndListsKnownOnes) {
  const auto r = validate(R"({"type": "Skill", "skill": "Localise", "params": {"object": "load"}})");
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/skill");
  EXPECT_NE(r.errors[0].message.find("unknown skill \"Localise\" (did you mean \"Localize\"?)"), std::string::npos)
      << r.errors[0].message;
  EXPECT_NE(r.errors[0].message.find("AttachRobotToLoad, CollaborativeMoveLoad"), std::string::npos);
  EXPECT_EQ(r.codes, std::vector<ErrorCode>{ErrorCode::kUnknownSkill});  // the controller waits for an executor on this code
}

TEST(RecipeSemantics, UnknownNamesCarryTheirCodeOtherErrorsDoNot) {
  // A monitor never succeeds, so one at the root also makes the recipe one that can never succeed.
  const auto m = validate(R"({"type": "Parallel", "success_threshold": 1, "failure_threshold": 1, "children": [)" + std::string(kLocalizeLoad) +
                          R"(, {"type": "Monitor", "monitor": "Nope"}]})");
  ASSERT_EQ(m.errors.size(), 1U) << dump(m);
  EXPECT_EQ(m.codes, std::vector<ErrorCode>{ErrorCode::kUnknownMonitor}) << dump(m);
  const auto c = validate(R"({"type": "Condition", "condition": "Nope"})");
  ASSERT_EQ(c.errors.size(), 1U) << dump(c);
  EXPECT_EQ(c.codes, std::vector<ErrorCode>{ErrorCode::kUnknownCondition});
  // A known skill of the wrong kind, or a schema error, is wrong as written.
  const auto k = validate(R"({"type": "Skill", "skill": "YankMonitor"})");
  ASSERT_EQ(k.errors.size(), 1U) << dump(k);
  EXPECT_EQ(k.codes, std::vector<ErrorCode>{ErrorCode::kInvalid});
  EXPECT_FALSE(only_unknown_leaves(k));
  const auto s = validate(R"({"type": "Skil", "skill": "Localize"})");
  ASSERT_FALSE(s.errors.empty());
  ASSERT_EQ(s.codes.size(), s.errors.size());
  for (const auto code : s.codes) EXPECT_EQ(code, ErrorCode::kInvalid);
  EXPECT_FALSE(only_unknown_leaves(c)) << "a condition comes from no executor";
  EXPECT_TRUE(only_unknown_leaves(m));
  // Mixed: an unknown skill next to a parameter error is not only unknown leaves; codes stay aligned.
  const auto mixed = validate(R"({"type": "Sequence", "children": [{"type": "Skill", "skill": "Nope"},
      {"type": "Skill", "skill": "Localize", "params": {"object": "load", "min_quality": "high"}}]})");
  ASSERT_EQ(mixed.errors.size(), 2U) << dump(mixed);
  ASSERT_EQ(mixed.codes.size(), 2U);
  EXPECT_EQ(mixed.errors[0].pointer, "/root/children/0/skill");
  EXPECT_EQ(mixed.codes[0], ErrorCode::kUnknownSkill);
  EXPECT_EQ(mixed.codes[1], ErrorCode::kInvalid);
  EXPECT_FALSE(only_unknown_leaves(mixed));
}

TEST(RecipeSemantics, WrongKindSaysWhatToWrite) {
  const auto r = validate(R"({"type": "Skill", "skill": "YankMonitor"})");
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/skill");
  EXPECT_NE(r.errors[0].message.find("is a monitor, not a skill"), std::string::npos);
  EXPECT_NE(r.errors[0].message.find("{\"type\": \"Monitor\", \"monitor\": \"YankMonitor\"}"), std::string::npos);
  const auto c = validate(R"({"type": "Condition", "condition": "Localize", "params": {"object": "x"}})");
  EXPECT_TRUE(has_error(c.errors, "/root/condition", "is a skill, not a condition")) << dump(c);
  const auto m = validate(R"({"type": "Monitor", "monitor": "Nope"})");
  EXPECT_TRUE(has_error(m.errors, "/root/monitor", "expected one of the library's monitors: ForceMonitor, "
                                                   "TimerMonitor, YankMonitor"))
      << dump(m);
}

TEST(RecipeSemantics, ParameterErrorsAllReportedWithPointers) {
  const auto r = validate(seq({
      R"({"type": "Skill", "skill": "Localize"})",
      R"({"type": "Skill", "skill": "Pick", "params": {"object": "load", "grasp": "grasp_side", "approach_speed_m_per_s": 2}})",
      R"({"type": "Monitor", "monitor": "YankMonitor", "params": {"max_yank_n_per_s": "high", "colour": 1}})",
      R"({"type": "Monitor", "monitor": "TimerMonitor", "params": {"max_duration_s": {"value": 5, "unit": "m"}}})",
  }));
  ASSERT_FALSE(r.ok());
  const auto& e = r.errors;
  EXPECT_TRUE(has_error(e, "/root/children/0/params/object", "missing required parameter")) << dump(r);
  EXPECT_TRUE(has_error(e, "/root/children/1/params/grasp", "feature reference")) << dump(r);
  EXPECT_TRUE(has_error(e, "/root/children/1/params/approach_speed_m_per_s", "in [0.005, 0.25] m/s, got 2 m/s"))
      << dump(r);
  EXPECT_TRUE(has_error(e, "/root/children/2/params/max_yank_n_per_s", "expected number in [1, 100000] N/s"))
      << dump(r);
  EXPECT_TRUE(has_error(e, "/root/children/2/params/colour", "unknown parameter")) << dump(r);
  EXPECT_TRUE(has_error(e, "/root/children/3/params/max_duration_s", "cannot be converted to \"s\"")) << dump(r);
}

// --- Thresholds and reachability ---------------------------------------------------------------

TEST(RecipeSemantics, ParallelThresholdsUnderTypedCounting) {
  const auto r = validate(par(2, 4, {kPickLoad, kYank, kForce}), {});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(has_error(r.errors, "/root/success_threshold",
                        "success_threshold 2 can never be reached: only 1 of 3 children can succeed (monitors never "
                        "do); expected 1..1"))
      << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/failure_threshold", "failure_threshold 4 exceeds the 3 children; expected 1..3"))
      << dump(r);
}

TEST(RecipeSemantics, ParallelOfMonitorsOnlyCanNeverSucceed) {
  const auto r = validate(seq({kLocalizeLoad, par(1, 1, {kYank, kForce})}));
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);  // the cause, not also "the Sequence is blocked"
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/success_threshold", "expected at least one child that can succeed"))
      << dump(r);
}

TEST(RecipeSemantics, SubtreesCountTowardsM) {
  const auto ok = validate(seq({kLocalizeLoad, par(2, 1, {seq({kPickLoad}), kLocalizeTarget, kYank})}));
  // Localize(target) claims the camera, Pick claims robot/gripper/load: no conflict.
  EXPECT_TRUE(ok.ok()) << dump(ok);
  const auto bad = validate(par(2, 1, {kLocalizeLoad, seq({kYank}), kForce}));
  EXPECT_TRUE(has_error(bad.errors, "/root/success_threshold", "only 1 of 3")) << dump(bad);
}

TEST(RecipeSemantics, MonitorInSequenceBlocksIt) {
  const auto r = validate(seq({kLocalizeLoad, kYank, kLocalizeTarget}));
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/children/1");
  EXPECT_NE(r.errors[0].message.find("a Monitor never succeeds, so the Sequence can never succeed"), std::string::npos);
}

TEST(RecipeSemantics, RetryOfMonitorAndMonitorRootRejected) {
  const auto retry = validate(R"({"type": "Retry", "max_attempts": 2, "child": )" + std::string(kYank) + "}");
  EXPECT_TRUE(has_error(retry.errors, "/root/child", "so the Retry can never succeed")) << dump(retry);
  const auto root = validate(kYank);
  EXPECT_TRUE(has_error(root.errors, "/root", "this recipe can never succeed")) << dump(root);
  const auto timeout = validate(R"({"type": "Timeout", "duration_s": 5, "child": )" + std::string(kYank) + "}");
  EXPECT_TRUE(has_error(timeout.errors, "/root", "this recipe can never succeed")) << dump(timeout);
}

TEST(RecipeSemantics, InvertedOrForcedMonitorIsFine) {
  EXPECT_TRUE(validate(seq({R"({"type": "Inverter", "child": )" + std::string(kForce) + "}", kLocalizeLoad})).ok());
  EXPECT_TRUE(validate(seq({R"({"type": "ForceSuccess", "child": {"type": "Timeout", "duration_s": 2, "child": )" +
                                std::string(kForce) + "}}",
                            kLocalizeLoad}))
                  .ok());
}

TEST(RecipeSemantics, DuplicateOptionLabels) {
  const auto r = validate(R"({"type": "OperatorDecision", "prompt": "?", "options": [
      {"label": "go", "child": )" + std::string(kLocalizeLoad) + R"(},
      {"label": "go", "child": )" + std::string(kLocalizeTarget) + "}]}");
  EXPECT_TRUE(has_error(r.errors, "/root/options/1/label", "duplicate option label")) << dump(r);
}

// --- Resources ---------------------------------------------------------------------------------

TEST(RecipeSemantics, ConcurrentBranchesMayNotShareAResource) {
  const auto r = validate(seq({kLocalizeLoad, par(2, 1, {kPickLoad, kLocalizeTarget, kPlaceLoad})}), {});
  ASSERT_FALSE(r.ok());
  // Pick and Place both claim robot, gripper and the load.
  // Place also lacks attached(robot,load): its sibling Pick does not certainly run before it.
  EXPECT_EQ(r.errors.size(), 2U) << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/children/2", "precondition \"attached(robot,load)\"")) << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/children/2",
                        "resources \"gripper\", \"load\", \"robot\" are claimed both by Skill Place at "
                        "/root/children/1/children/2 and by Skill Pick at /root/children/1/children/0, which run "
                        "concurrently under the Parallel at /root/children/1"))
      << dump(r);
}

TEST(RecipeSemantics, SequenceAndFallbackInsideOneBranchMayReuseResources) {
  const auto r = validate(
      seq({kLocalizeLoad, par(1, 1, {seq({kPickLoad, kPlaceLoad}), kYank}), composite("Fallback", {kPickLoad, kPickLoad})}));
  EXPECT_TRUE(r.ok()) << dump(r);
}

TEST(RecipeSemantics, ParameterDependentResourcesConflictOnlyOnTheSameObject) {
  const std::string localize_both = seq({kLocalizeLoad,
                                         R"({"type": "Skill", "skill": "Localize", "params": {"object": "box"}})"});
  const std::string pick_box = R"({"type": "Skill", "skill": "Pick", "params": {"object": "box", "grasp": "box/top"}})";
  const std::string move_load = R"({"type": "Skill", "skill": "CollaborativeMoveLoad", "params": {"object": "load"}})";
  // Pick(box) claims robot: conflicts with CollaborativeMoveLoad(load) on robot but not on the object.
  const auto r = validate(seq({localize_both, kPickLoad, par(2, 1, {pick_box, move_load})}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/2/children/1", "resource \"robot\"")) << dump(r);
  EXPECT_FALSE(has_error(r.errors, "/root/children/2/children/1", "\"load\"")) << dump(r);
  EXPECT_FALSE(has_error(r.errors, "/root/children/2/children/1", "\"box\"")) << dump(r);
}

TEST(RecipeSemantics, NestedParallelConflictsFound) {
  const auto r = validate(seq({kLocalizeLoad, kLocalizeTarget,
                               par(1, 1, {seq({kPickLoad}), par(1, 1, {kLocalizeLoad, kYank})}),
                               par(1, 1, {par(1, 1, {kLocalizeTarget, kForce}), kLocalizeLoad})}));
  // The first Parallel is fine (robot vs camera); the second runs two Localize (camera) at once.
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/children/3/children/1");
  EXPECT_NE(r.errors[0].message.find("\"camera\""), std::string::npos);
}

// --- Preconditions -----------------------------------------------------------------------------

TEST(RecipePreconditions, SequencePredecessorEstablishes) {
  EXPECT_TRUE(validate(seq({kLocalizeLoad, kPickLoad, kPlaceLoad})).ok());
}

TEST(RecipePreconditions, MissingPreconditionNamesFact) {
  const auto r = validate(seq({kPickLoad}));
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/children/0");
  EXPECT_NE(r.errors[0].message.find("precondition \"localized(load)\" of Skill Pick may not hold"), std::string::npos)
      << r.errors[0].message;
}

TEST(RecipePreconditions, LaterSkillDoesNotCount) {
  const auto r = validate(seq({kPickLoad, kLocalizeLoad}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/0", "established by Skill Localize at /root/children/1")) << dump(r);
}

TEST(RecipePreconditions, FallbackAlternativeDoesNotCount) {
  // Localize may have failed and the Condition succeeded instead — either way localized(load)
  // holds after the Fallback. But inside the Fallback, Pick after a failed Localize may not rely on it.
  EXPECT_TRUE(validate(seq({composite("Fallback", {kLocalizeLoad, R"({"type": "Condition", "condition": "ObjectLocalized", "params": {"object": "load"}})"}),
                            kPickLoad}))
                  .ok());
  const auto r = validate(composite("Fallback", {kLocalizeLoad, kPickLoad}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/1", "precondition \"localized(load)\"")) << dump(r);
  // After a Fallback only facts every alternative establishes hold.
  const auto partial = validate(seq({composite("Fallback", {kLocalizeLoad, kLocalizeTarget}), kPickLoad}));
  EXPECT_TRUE(has_error(partial.errors, "/root/children/1", "precondition \"localized(load)\"")) << dump(partial);
}

TEST(RecipePreconditions, ParallelSiblingDoesNotCount) {
  const auto r = validate(par(2, 1, {kLocalizeLoad, kPickLoad}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/1", "precondition \"localized(load)\"")) << dump(r);
}

TEST(RecipePreconditions, ParallelResultsCountAfterItOnlyWhenAllMustSucceed) {
  const std::string loc_box = R"({"type": "Skill", "skill": "Localize", "params": {"object": "box"}})";
  const std::string pick_box = R"({"type": "Skill", "skill": "Pick", "params": {"object": "box", "grasp": "box/top"}})";
  // Localize(load) and ObjectLocalized(box) in parallel, M = 2 = both: both facts hold after.
  const std::string cond_box = R"({"type": "Condition", "condition": "ObjectLocalized", "params": {"object": "box"}})";
  EXPECT_TRUE(validate(seq({par(2, 1, {kLocalizeLoad, cond_box}), pick_box})).ok());
  // M = 1 of 2: either may have been the one that succeeded.
  const auto r = validate(seq({par(1, 2, {kLocalizeLoad, cond_box}), pick_box}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/1", "precondition \"localized(box)\"")) << dump(r);
  (void)loc_box;
}

TEST(RecipePreconditions, ConditionEstablishesItsFact) {
  EXPECT_TRUE(validate(seq({R"({"type": "Condition", "condition": "ObjectLocalized", "params": {"object": "load"}})",
                            kPickLoad}))
                  .ok());
}

TEST(RecipePreconditions, DeletedFactNoLongerHolds) {
  // Place deletes attached(robot,load); a second Place needs it again.
  const auto r = validate(seq({kLocalizeLoad, kPickLoad, kPlaceLoad, kPlaceLoad}));
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/children/3");
  EXPECT_NE(r.errors[0].message.find("attached(robot,load)"), std::string::npos);
}

TEST(RecipePreconditions, RetryAttemptsMayFindFactsUndone) {
  // A failed Place may already have released the load: a second attempt cannot rely on attached().
  const auto r = validate(seq({kLocalizeLoad, kPickLoad,
                               R"({"type": "Retry", "max_attempts": 2, "child": )" + std::string(kPlaceLoad) + "}"}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/2/child", "attached(robot,load)")) << dump(r);
  // A single attempt is just the skill.
  EXPECT_TRUE(validate(seq({kLocalizeLoad, kPickLoad,
                            R"({"type": "Retry", "max_attempts": 1, "child": )" + std::string(kPlaceLoad) + "}"}))
                  .ok());
  // Retrying the pair re-establishes the fact inside each attempt.
  EXPECT_TRUE(validate(seq({kLocalizeLoad, R"({"type": "Retry", "max_attempts": 3, "child": )" +
                                               seq({kPickLoad, kPlaceLoad}) + "}"}))
                  .ok());
}

TEST(RecipePreconditions, ConcurrentDeletionInvalidatesSiblingPrecondition) {
  // Inside a Parallel a sibling's deletion can happen at any time.
  const std::string release_first = seq({kLocalizeLoad, kPickLoad, par(2, 1, {kPlaceLoad, seq({kLocalizeTarget,
      R"({"type": "Skill", "skill": "Screw", "params": {"holes": ["target/h1"]}})"})})});
  const auto r = validate(release_first);
  EXPECT_TRUE(has_error(r.errors, "/root/children/2/children/1/children/1", "inserted(load,target)")) << dump(r);
}

TEST(RecipePreconditions, InitialFactsAndAssumptions) {
  ValidatorOptions options;
  options.initial_facts = {"localized( load )", "not a fact"};
  EXPECT_TRUE(validate(kPickLoad, options).ok());
  const auto with_assumption = RecipeValidator(example_library()).validate_text(
      R"J({"recipe_version": 1, "task_id": "t", "assumptions": ["localized(load)"], "root": )J" + std::string(kPickLoad) +
      "}");
  ASSERT_TRUE(with_assumption.ok()) << format_errors(with_assumption.errors);
  EXPECT_EQ(with_assumption.recipe->assumptions, std::vector<std::string>{"localized(load)"});
}

TEST(RecipePreconditions, OperatorBranchesEachStartFromTheSameFacts) {
  const auto r = validate(seq({kLocalizeLoad, R"({"type": "OperatorDecision", "prompt": "?", "options": [
      {"label": "pick", "child": )" + std::string(kPickLoad) + R"(},
      {"label": "place", "child": )" + std::string(kPlaceLoad) + "}]}"}));
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/options/1/child", "attached(robot,load)")) << dump(r);
  EXPECT_FALSE(has_error(r.errors, "/root/children/1/options/0/child", "precondition")) << dump(r);
}

TEST(RecipePreconditions, SkippedWhenALeafIsUnresolved) {
  // Unknown Localise: reporting Pick's unmet precondition too would only echo that error.
  const auto r = validate(seq({R"({"type": "Skill", "skill": "Localise", "params": {"object": "load"}})", kPickLoad}));
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
}

// --- Everything at once --------------------------------------------------------------------------

TEST(RecipeSemantics, EveryKindOfSemanticErrorReportedTogether) {
  const auto r = validate(seq({
      R"({"type": "Skill", "skill": "Localize", "params": {"object": "load", "min_quality": 2}})",
      par(3, 1, {kPickLoad, kPlaceLoad, kYank}),
      kForce,
  }));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(has_error(r.errors, "/root/children/0/params/min_quality", "in [0, 1]")) << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/success_threshold", "only 2 of 3")) << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/children/1/children/1", "\"robot\" are claimed both")) << dump(r);
  EXPECT_TRUE(has_error(r.errors, "/root/children/2", "a Monitor never succeeds")) << dump(r);
}

TEST(RecipeSemantics, NodeLimit) {
  ValidatorOptions options;
  options.limits.max_nodes = 3;
  const auto r = validate(seq({kLocalizeLoad, kLocalizeTarget, kLocalizeLoad}), options);
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/root/children/2");
  EXPECT_NE(r.errors[0].message.find("more than 3 nodes"), std::string::npos);
}

TEST(RecipeSemantics, InvalidAssumptionRejected) {
  const auto r = RecipeValidator(example_library()).validate_document(nlohmann::json::parse(
      R"J({"recipe_version": 1, "task_id": "t", "assumptions": ["ok()", "ready"], "root": )J" + std::string(kLocalizeLoad) +
      "}"));
  EXPECT_TRUE(r.ok()) << format_errors(r.errors);
  EXPECT_EQ(r.recipe->assumptions, (std::vector<std::string>{"ok()", "ready()"}));
}

}  // namespace
}  // namespace rigger::recipe
