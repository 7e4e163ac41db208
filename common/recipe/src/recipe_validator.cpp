#include "rigger/recipe/recipe_validator.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "rigger/recipe/recipe_schema.hpp"
#include "tree_checks.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::recipe {
namespace {

using Json = nlohmann::json;

// The schema validator and the tree builder recurse; a document that did not come through the
// bounded parser could be arbitrarily deep, so measure first, without recursion.
std::size_t depth_of(const Json& document, std::size_t stop_at) {
  std::size_t deepest = 0;
  std::vector<std::pair<const Json*, std::size_t>> stack{{&document, 1}};
  while (!stack.empty()) {
    const auto [value, depth] = stack.back();
    stack.pop_back();
    if (!value->is_structured()) {
      continue;
    }
    deepest = std::max(deepest, depth);
    if (deepest > stop_at) {
      return deepest;
    }
    for (const auto& child : *value) {
      stack.emplace_back(&child, depth + 1);
    }
  }
  return deepest;
}

std::optional<skill::Fact> canonical_fact(const std::string& text) {
  const auto predicate = skill::parse_predicate(text);
  if (!predicate || predicate->negated || !predicate->referenced_params().empty()) {
    return std::nullopt;
  }
  return predicate->to_string();
}

// The pointer goes into the Error's own field; the message carries the file and position.
Error parse_error(const rigger::JsonParseError& e) {
  std::string where = e.source.empty() ? "" : e.source + ": ";
  where += "line " + std::to_string(e.line) + ", column " + std::to_string(e.column) + ": ";
  return {e.pointer, where + e.message};
}

}  // namespace

RecipeValidator::RecipeValidator(skill::SkillLibrary library, ValidatorOptions options)
    : library_(std::move(library)), options_(std::move(options)) {
  for (const auto& f : options_.initial_facts) {
    if (const auto fact = canonical_fact(f)) {
      initial_facts_.push_back(*fact);
    }
  }
  (void)SchemaValidator::recipe();  // compile the schema now rather than on the first recipe
}

ValidationResult RecipeValidator::validate_text(std::string_view text) const {
  return validate_parsed(rigger::parse_json_bounded(text, json_limits()));
}

ValidationResult RecipeValidator::validate_file(const std::filesystem::path& path) const {
  return validate_parsed(rigger::parse_json_file_bounded(path, json_limits()));
}

rigger::JsonLimits RecipeValidator::json_limits() const {
  rigger::JsonLimits limits;
  limits.max_bytes = options_.limits.max_bytes;
  limits.max_depth = options_.limits.max_depth;
  return limits;
}

ValidationResult RecipeValidator::validate_parsed(const rigger::JsonParseResult& parsed) const {
  if (!parsed.ok()) {
    ValidationResult result;
    result.errors.push_back(parse_error(*parsed.error));
    result.codes.push_back(ErrorCode::kInvalid);
    return result;
  }
  return validate_document(parsed.value);
}

ValidationResult RecipeValidator::validate_document(const Json& document) const {
  ValidationResult result = check_document(document);
  result.codes.resize(result.errors.size(), ErrorCode::kInvalid);  // every error not coded is kInvalid
  return result;
}

ValidationResult RecipeValidator::check_document(const Json& document) const {
  ValidationResult result;
  auto& errors = result.errors;
  if (depth_of(document, options_.limits.max_depth) > options_.limits.max_depth) {
    errors.push_back({"", "nesting deeper than " + std::to_string(options_.limits.max_depth) +
                              " levels: expected at most " + std::to_string(options_.limits.max_depth)});
    return result;
  }
  errors = SchemaValidator::recipe().validate(document);
  if (!errors.empty()) {
    return result;
  }

  ValidatedRecipe recipe;
  recipe.recipe_version = document["recipe_version"].get<int>();
  recipe.task_id = document["task_id"].get<std::string>();
  recipe.description = document.value("description", "");
  std::vector<skill::Fact> initial = initial_facts_;
  if (document.contains("assumptions")) {
    const auto& assumptions = document["assumptions"];
    for (std::size_t i = 0; i < assumptions.size(); ++i) {
      if (const auto fact = canonical_fact(assumptions[i].get<std::string>())) {
        recipe.assumptions.push_back(*fact);
        initial.push_back(*fact);
      } else {
        errors.push_back({"/assumptions/" + std::to_string(i),
                          "expected a ground fact like \"hooked(crane,load)\" (no \"!\", no \"$param\")"});
      }
    }
  }
  const bt::Seconds stop_timeout =
      document.contains("stop_timeout_s") ? bt::Seconds(document["stop_timeout_s"].get<double>())
                                          : options_.default_stop_timeout;

  detail::BuiltTree built = detail::build_tree(document["root"], library_, options_.limits, stop_timeout, errors, result.codes);
  if (!built.complete) {
    return result;
  }
  detail::check_reachability(built.tree, errors);
  detail::check_resources(built.tree, errors);
  // Preconditions need every leaf's pre- and postconditions; with an unresolved leaf the flow
  // analysis would report consequences of that error rather than new ones.
  if (built.leaves_resolved) {
    detail::check_preconditions(built, initial, errors);
  }
  if (!errors.empty()) {
    return result;
  }
  try {
    bt::check_tree_spec(built.tree);
  } catch (const bt::SpecError& e) {
    // Unreachable for a schema-valid recipe; kept so that a gap between the two checks shows
    // up as a rejection rather than as an engine that refuses to start.
    errors.push_back({"", std::string("internal check failed: ") + e.what()});
    return result;
  }
  std::set<std::string> resources;
  for (const auto& node : built.tree.nodes) {
    resources.insert(node.resources.begin(), node.resources.end());
  }
  recipe.resources.assign(resources.begin(), resources.end());
  recipe.tree = std::move(built.tree);
  result.recipe = std::move(recipe);
  return result;
}

bool only_unknown_leaves(const ValidationResult& result) {
  return !result.errors.empty() && result.codes.size() == result.errors.size() &&
         std::all_of(result.codes.begin(), result.codes.end(), [](ErrorCode c) {
           return c == ErrorCode::kUnknownSkill || c == ErrorCode::kUnknownMonitor;
         });
}

std::string format_errors(const std::vector<Error>& errors) {
  std::string out;
  for (const auto& e : errors) {
    out += e.to_string();
    out += "\n";
  }
  return out;
}

}  // namespace rigger::recipe
