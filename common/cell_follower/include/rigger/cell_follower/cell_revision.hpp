#pragma once
/// @file
/// Reading a cell revision (rigger/world/cell) as a reader of the cell file takes it: the document parsed
/// and validated by the cell file loader (rigger_cell_config) with the reader's own configured cell file
/// as its source, so errors name that file and relative model paths resolve against that file's folder
/// (cell::cell_model_folder); every STEP model the revision names must exist there. Pure: no DDS.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "rigger/base/time.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::cell_follower {

/// A revision a reader can take: the validated cell (CAD rules not derived: a reader that needs their
/// poses calls cell::derive_cad_features with `model_dir`) and what changed.
struct FollowedRevision {
  std::uint64_t revision = 0;
  std::uint64_t previous_revision = 0;
  cell::CellFile cell;
  nlohmann::json document;  ///< cell_json parsed: the revision's document (for an object-level diff)
  std::filesystem::path model_dir;  ///< where the cell's relative model paths resolve (this reader's cell folder)
  nlohmann::json changes = nlohmann::json::object();  ///< changes_json parsed (see world_protocol::CellRevision)
  std::string sha256;
  std::string who;
  std::string comment;
  WallTime stamp{};
};

/// The outcome of reading one revision: `revision` when it can be taken, else `refusal` says why, naming
/// the revision, the file, the JSON pointer and what was expected.
struct RevisionReading {
  std::optional<FollowedRevision> revision;
  std::string refusal;
};

/// Reads `sent` as the reader whose configured cell file is `cell_file`. Never throws.
RevisionReading read_revision(const world_protocol::CellRevision& sent, const std::filesystem::path& cell_file);

}  // namespace rigger::cell_follower
