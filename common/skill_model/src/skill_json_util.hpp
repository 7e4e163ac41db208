#pragma once
// Small helpers for reading and describing JSON in error messages. Internal to rigger_skill_model.

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"
#include "rigger/skill/json_text.hpp"
#include "rigger/skill/model_error.hpp"

namespace rigger::skill::detail {

using skill::describe_json;
using skill::format_number;

/// "a, b, c" (each in double quotes when `quote`).
std::string join(const std::vector<std::string_view>& items, bool quote = false);
std::string join(const std::vector<std::string>& items, bool quote = false);

/// One error per key of `object` not in `allowed`.
void check_keys(const nlohmann::json& object, const std::string& pointer, std::initializer_list<std::string_view> allowed,
                std::vector<ModelError>& errors);

enum class IdentifierStyle {
  kSnake,   ///< [a-z][a-z0-9_]*  (parameter names)
  kPascal,  ///< [A-Z][A-Za-z0-9_]*  (skill names)
};

/// True when `text` is a non-empty identifier of `style` of at most 64 characters.
bool is_identifier(std::string_view text, IdentifierStyle style);

/// Reads the required identifier `object[key]` into `out`, or records why it is not one.
void read_identifier(const nlohmann::json& object, const char* key, const std::string& pointer, IdentifierStyle style,
                     std::string& out, std::vector<ModelError>& errors);

}  // namespace rigger::skill::detail
