#pragma once
/// A JSON parser for untrusted input that enforces its bounds while it parses.
///
/// Recipes, skill descriptions and library files come from other processes or from people.
/// The size is checked before a byte is parsed, the nesting depth is checked at every '{' and '['
/// (so a 1,000,000-deep "[[[[…" is refused at depth limit + 1 without recursion or a big
/// allocation), invalid UTF-8 is refused with its byte position, and duplicate object keys
/// (which other parsers resolve differently) are refused with their JSON pointer.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rigger {

/// Bounds applied while parsing.
struct JsonLimits {
  /// Largest accepted input, in bytes. Checked before parsing starts.
  std::size_t max_bytes = 4U * 1024U * 1024U;
  /// Largest accepted nesting depth: the top-level value has depth 1 when it is an object or array.
  std::size_t max_depth = 128;
};

/// Why a text is not acceptable JSON: where (byte offset, 1-based line and column, and when known
/// the JSON pointer of the enclosing value) and what was expected.
struct JsonParseError {
  std::string source;   ///< file name or "" for in-memory text
  std::size_t offset = 0;  ///< byte offset from the start of the text (0-based)
  std::size_t line = 1;    ///< 1-based line of `offset`
  std::size_t column = 1;  ///< 1-based byte column of `offset`
  std::string pointer;     ///< JSON pointer of the offending value when known, "" otherwise
  std::string message;     ///< human-readable reason, says what was expected

  /// "source:line:column: message" (source omitted when empty).
  std::string to_string() const;
};

/// Outcome of a bounded parse: a value or an error, never both.
struct JsonParseResult {
  nlohmann::json value;
  std::optional<JsonParseError> error;
  bool ok() const { return !error.has_value(); }
};

/// Parses `text` as one JSON document (no comments, nothing but whitespace after it).
/// Never throws for bad input: returns an error naming the position and what was expected.
/// Thread safety: reentrant.
JsonParseResult parse_json_bounded(std::string_view text, const JsonLimits& limits = {});

/// Reads and parses a file; its size is checked against `limits.max_bytes` before it is read.
/// Errors (missing file, unreadable, too large, bad JSON) are returned with `source` = the path.
JsonParseResult parse_json_file_bounded(const std::filesystem::path& path, const JsonLimits& limits = {});

/// Escapes one JSON pointer reference token ("~" → "~0", "/" → "~1").
std::string escape_pointer_token(std::string_view token);

}  // namespace rigger
