#pragma once
/// The recipe JSON Schema (recipes/schema/recipe.schema.json) and its compiled validator.

#include <memory>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/model_error.hpp"

namespace rigger::recipe {

/// The text of recipes/schema/recipe.schema.json, compiled into the binary at build time.
std::string_view recipe_schema_text();

/// A compiled JSON Schema (draft-07, valijson) that reports every error with its JSON pointer
/// and, for the recipe schema, what was expected there.
class SchemaValidator {
 public:
  /// Compiles `schema`. Throws std::runtime_error when it is not a usable draft-07 schema.
  explicit SchemaValidator(const nlohmann::json& schema);
  ~SchemaValidator();
  SchemaValidator(const SchemaValidator&) = delete;
  SchemaValidator& operator=(const SchemaValidator&) = delete;

  /// Every error of `document` (empty when valid). Wrapper errors ("failed to validate item #3")
  /// are dropped in favour of the errors that caused them. Thread-safe.
  std::vector<skill::ModelError> validate(const nlohmann::json& document) const;

  /// The recipe schema, compiled on first use (thread-safe) and kept for the process.
  static const SchemaValidator& recipe();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigger::recipe
