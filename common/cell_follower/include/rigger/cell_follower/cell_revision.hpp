#pragma once
/// @file
/// Reading a cell revision (rigger/world/cell) as a reader of the cell file takes it: the document parsed
/// and validated by the cell file loader (rigger_cell_config) with the reader's own configured cell file
/// as its source, so errors name that file and relative model paths resolve against that file's folder
/// (cell::cell_model_folder); every STEP model the revision names must exist there, or, when the revision
/// pins it by sha256, among the models the reader received. Pure: no DDS.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/time.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/cell_config/cell_models.hpp"
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

/// The outcome of reading one revision: `revision` when it can be taken; else `missing` when only pinned
/// models are lacking (they may still come on rigger/world/cell_model), else `refusal` says why, naming
/// the revision, the file, the JSON pointer and what was expected.
struct RevisionReading {
  std::optional<FollowedRevision> revision;
  std::vector<cell::MissingModel> missing;
  std::string refusal;
};

/// Where a reader keeps the models it received: the store, and the root of the folders of links made
/// for revisions that read from it (cell::resolve_models).
struct ReceivedModels {
  const cell::ModelStore* store = nullptr;
  std::filesystem::path links_root;
};

/// Reads `sent` as the reader whose configured cell file is `cell_file`; a pinned model its folder lacks
/// is taken from `received`. Never throws.
RevisionReading read_revision(const world_protocol::CellRevision& sent, const std::filesystem::path& cell_file,
                              const ReceivedModels& received = {});

}  // namespace rigger::cell_follower
