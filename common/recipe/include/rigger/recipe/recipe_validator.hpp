#pragma once
/// From recipe text to a validated behaviour tree (docs/recipes.md), or to the list of every error.
///
/// Stages, each reporting every error it finds with a JSON pointer and what was expected:
///  1. bounded parsing: size checked before parsing, nesting depth checked while parsing,
///     invalid UTF-8 and duplicate keys refused (rigger/base/bounded_json.hpp);
///  2. JSON Schema (recipes/schema/recipe.schema.json, draft-07, compiled into the binary);
///  3. semantics against a skill library: skills/monitors/conditions known and of the right
///     kind, parameters typed, ranged and unit-checked with defaults filled in, Parallel
///     thresholds feasible under typed counting, no resource claimed by two concurrent branches
///     of a Parallel, nodes that can never succeed where success is required, and every skill's
///     preconditions established by the initial facts or by skills that certainly ran before it.
/// Stage 3 runs only on a schema-valid document.

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/bt/tree_spec.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/skill/model_error.hpp"
#include "rigger/skill/predicate.hpp"
#include "rigger/skill/skill_library.hpp"

namespace rigger::recipe {

/// One problem in a recipe: JSON pointer ("" = the whole document), message saying what was
/// expected, and its kind (ErrorCode). Shared with the skill model.
using Error = skill::ModelError;

/// What kind of problem an Error is, for code that acts on the kind (never on the message text).
enum class ErrorCode {
  kInvalid,           ///< the recipe is wrong as written (every error not listed below)
  kUnknownSkill,      ///< names a skill the library does not have (yet: an executor may announce it)
  kUnknownMonitor,    ///< names a monitor the library does not have (likewise)
  kUnknownCondition,  ///< names a condition the library does not have
};

/// Version of the recipe format this code reads.
inline constexpr int kRecipeVersion = 1;

/// The largest Limits::max_bytes a controller can be configured with ("max_recipe_bytes"): a bigger
/// recipe is refused by every controller (riggerctl run says so before publishing it).
inline constexpr std::size_t kMaxRecipeBytesCeiling = 64U * 1024U * 1024U;

/// Bounds on untrusted recipes.
struct Limits {
  std::size_t max_bytes = 4U * 1024U * 1024U;  ///< refused before parsing when larger
  std::size_t max_depth = 128;                 ///< JSON nesting (a tree level costs 2–3 JSON levels)
  std::size_t max_nodes = 50'000;              ///< behaviour-tree nodes
};

struct ValidatorOptions {
  Limits limits;
  /// Stop timeout of a Skill or Monitor when neither it nor an ancestor nor the recipe sets one.
  bt::Seconds default_stop_timeout{5.0};
  /// Facts known to hold in the world when the task starts (e.g. from the world model), in
  /// predicate form "hooked(crane,load)". Unparseable entries are ignored.
  std::vector<skill::Fact> initial_facts;
};

/// A recipe that passed every check, ready for bt::Engine.
struct ValidatedRecipe {
  int recipe_version = kRecipeVersion;
  std::string task_id;
  std::string description;
  /// The recipe's "assumptions", canonical form.
  std::vector<skill::Fact> assumptions;
  /// The tree: ids "root", "root/0", …; pointers into the recipe; parameters with defaults
  /// filled in and quantities converted to SI; resources resolved; stop timeouts effective.
  bt::TreeSpec tree;
  /// Every resource any leaf claims, sorted and unique (for admitting concurrent tasks).
  std::vector<std::string> resources;
};

struct ValidationResult {
  std::optional<ValidatedRecipe> recipe;  ///< set exactly when `errors` is empty
  std::vector<Error> errors;
  std::vector<ErrorCode> codes;  ///< codes[i] is the kind of errors[i] (same length)
  bool ok() const { return recipe.has_value(); }
};

/// Validates recipes against one skill library. Construction is cheap (the schema is compiled
/// once per process). const methods may be called from several threads at once.
class RecipeValidator {
 public:
  explicit RecipeValidator(skill::SkillLibrary library, ValidatorOptions options = {});

  /// Parses (bounded) and validates recipe text. Never throws on bad input.
  ValidationResult validate_text(std::string_view text) const;
  /// Validates an already parsed document (stages 2 and 3). Never throws on bad input.
  ValidationResult validate_document(const nlohmann::json& document) const;
  /// Reads (size checked first) and validates a file; errors about the file name it.
  ValidationResult validate_file(const std::filesystem::path& path) const;

  const skill::SkillLibrary& library() const { return library_; }
  const ValidatorOptions& options() const { return options_; }

 private:
  rigger::JsonLimits json_limits() const;
  ValidationResult validate_parsed(const rigger::JsonParseResult& parsed) const;
  ValidationResult check_document(const nlohmann::json& document) const;  ///< validate_document without codes padding

  skill::SkillLibrary library_;
  ValidatorOptions options_;
  std::vector<skill::Fact> initial_facts_;
};

/// Whether there are errors and every one names a skill or monitor the library does not have.
bool only_unknown_leaves(const ValidationResult& result);

/// "pointer: message" per line, for riggerctl and logs.
std::string format_errors(const std::vector<Error>& errors);

}  // namespace rigger::recipe
