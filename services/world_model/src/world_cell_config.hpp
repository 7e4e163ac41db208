#pragma once
/// @file
/// The world model's names for the shared cell-file reader (rigger_cell_config, format in
/// docs/world-model.md): a CellConfig is a validated cell::CellFile, and WorldStore::from_config turns
/// its entities into the store's. Errors are cell::CellFileError ("<file>: <pointer>: expected ...").

#include <filesystem>
#include <string>
#include <string_view>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::world {

using CellConfig = cell::CellFile;
using CellConfigError = cell::CellFileError;

/// Reads and validates the cell file at `path`. @throws CellConfigError.
inline CellConfig load_cell_config(const std::filesystem::path& path) {
  return cell::load_cell_file(path);
}

/// Parses and validates cell file text; `source` names it in errors. @throws CellConfigError.
inline CellConfig parse_cell_config(std::string_view text, const std::string& source) {
  return cell::parse_cell_file(text, source);
}

}  // namespace rigger::world
