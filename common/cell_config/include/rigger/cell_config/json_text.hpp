#pragma once
/// @file
/// Small helpers for JSON error messages: RFC 6901 pointers, short renderings of offending values,
/// and the form of entity and feature ids. Stateless, thread-safe.

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rigger::cell {

/// Appends `key` to JSON pointer `base`, escaping '~' and '/' as RFC 6901 requires.
std::string join_pointer(const std::string& base, std::string_view key);

/// A short rendering of a JSON value for error messages, e.g. `string "abc"` or `array [1,2]`
/// (at most about 80 characters).
std::string describe_json(const nlohmann::json& value);

/// True for 1 to 64 characters from [A-Za-z0-9_.-]: the form of entity and feature ids.
bool is_valid_identifier(std::string_view text);

}  // namespace rigger::cell
