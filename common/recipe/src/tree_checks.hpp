#pragma once
// Internal to rigger_recipe: building the TreeSpec from a schema-valid recipe and the semantic
// checks on it. Split out of recipe_validator.cpp so each check can be read (and tested) alone.

#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/bt/tree_spec.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/skill/predicate.hpp"
#include "rigger/skill/skill_library.hpp"

namespace rigger::recipe::detail {

/// Ground pre/postconditions of one leaf (empty for control nodes).
struct LeafFacts {
  std::vector<skill::Fact> preconditions;
  std::vector<skill::Fact> added;
  std::vector<skill::Fact> deleted;
};

struct BuiltTree {
  bt::TreeSpec tree;               ///< nodes in pre-order: every descendant has a larger index
  std::vector<LeafFacts> facts;    ///< indexed like tree.nodes
  bool leaves_resolved = true;     ///< every leaf named a known description and had valid params
  bool complete = true;            ///< false when a limit stopped the build
};

/// Builds the tree from the schema-valid `root` object at JSON pointer "/root". Records unknown
/// names, wrong kinds, parameter errors, duplicate option labels and limit violations; `codes` gets
/// the kind of each error it adds (and kInvalid for those before, so that it is as long as `errors`).
BuiltTree build_tree(const nlohmann::json& root, const skill::SkillLibrary& library, const Limits& limits,
                     bt::Seconds default_stop_timeout, std::vector<Error>& errors, std::vector<ErrorCode>& codes);

/// Parallel thresholds feasible under typed counting; no Sequence/Retry/Repeat child (and not
/// the root) that can never succeed. Reports the cause, not its consequences up the tree.
void check_reachability(const bt::TreeSpec& tree, std::vector<Error>& errors);

/// No resource claimed by two concurrent branches of a Parallel.
void check_resources(const bt::TreeSpec& tree, std::vector<Error>& errors);

/// Every precondition holds when its leaf starts: in `initial`, or established by a leaf that
/// certainly ran (and succeeded) before, and not possibly deleted since.
void check_preconditions(const BuiltTree& built, const std::vector<skill::Fact>& initial, std::vector<Error>& errors);

}  // namespace rigger::recipe::detail
