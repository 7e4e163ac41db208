#pragma once
/// @file
/// Loader of the cell configuration (`deploy/cell/*.json`, format in docs/world-model.md): the frame
/// tree, device poses, camera intrinsics, object models and CAD features. Every rule is checked at
/// load time; the first violation throws a CellConfigError naming the file, the JSON pointer and
/// what was expected. Unknown keys are rejected (a typo must not silently drop a setting); a
/// "comment" key is allowed in every object.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "world_types.hpp"

namespace rigger::world {

/// A cell configuration violation. `what()` reads "<file>: <pointer>: expected <expected>[, got <got>]".
class CellConfigError : public std::runtime_error {
 public:
  CellConfigError(std::string file, std::string pointer, std::string expected, std::string got = {});

  /// The file name (or the source name given to the parser).
  const std::string& file() const { return file_; }
  /// RFC 6901 JSON pointer of the offending value ("" for the whole document).
  const std::string& pointer() const { return pointer_; }
  /// What was expected there, in words.
  const std::string& expected() const { return expected_; }

 private:
  std::string file_;
  std::string pointer_;
  std::string expected_;
};

/// A validated cell configuration. Entity poses carry no stamp yet (see WorldStore::from_config).
struct CellConfig {
  std::string source;       ///< the file (or source name) it was read from
  int cell_version = 0;     ///< always kCellVersion
  std::string description;
  std::vector<Entity> entities;  ///< in file order; parents are known, ids unique, no cycles
};

/// The only format version this loader reads.
inline constexpr int kCellVersion = 1;
/// Inputs larger than this are refused before parsing (bytes).
inline constexpr std::size_t kMaxCellConfigBytes = 4 * 1024 * 1024;
/// JSON nesting deeper than this is refused while parsing.
inline constexpr int kMaxCellConfigDepth = 32;

/// Reads and validates the cell configuration file at `path`.
/// @throws CellConfigError on an unreadable file or any violation.
CellConfig load_cell_config(const std::filesystem::path& path);

/// Parses and validates configuration text; `source` names it in errors.
/// @throws CellConfigError on malformed JSON, oversized or too deeply nested input, or any violation.
CellConfig parse_cell_config(std::string_view text, const std::string& source);

/// Validates an already parsed document (e.g. built in code); `source` names it in errors.
/// @throws CellConfigError on any violation (including NaN or infinite numbers).
CellConfig cell_config_from_json(const nlohmann::json& document, const std::string& source);

}  // namespace rigger::world
