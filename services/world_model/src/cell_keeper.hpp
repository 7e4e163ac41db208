#pragma once
/// @file
/// The cell's revisions in the world model (docs/world-model.md, "Cell revisions"): which document the
/// world model runs on, what a request on rigger/world/cell_request does, and the history on disk. Pure
/// C++ over the cell file loader, the CAD derivation and the history folder; no DDS (the node publishes
/// and applies what this decides).
///
/// At start: the newest revision in the history that was made from this same cell file (absolute path)
/// while the file held the bytes it holds now is the running one; otherwise the file itself becomes a new
/// revision (the first, or one on top of the history when the file was edited since).
///
/// A proposed document goes through what the start goes through (the cell file rules, the CAD
/// derivation from the STEP models in the configured cell file's folder or, for a model the document pins
/// by sha256 and the folder lacks, from the models uploaded with a request (kept by sha256 in `models/`
/// of the history folder), the store built from it), then
/// the diff against the running revision and the held resources: all or nothing, and nothing changes on
/// a refusal.
///
/// Thread safety: none; the world model's loop thread owns it.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cell_history.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/cell_config/cell_models.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::world {

/// Bounds of a cell request's strings (bytes); cell_json's is cell::kMaxCellFileBytes.
inline constexpr std::size_t kMaxCellWhoBytes = 256;
inline constexpr std::size_t kMaxCellCommentBytes = 4096;
/// Code of a reply when the new revision could not be written to the history (nothing changed).
inline constexpr const char* kCellNotSaved = "NOT_SAVED";

/// A resource a running skill holds (rigger/skill/executors), "$param" already resolved to an entity id.
struct HeldResource {
  std::string resource;
  std::string executor;
  std::string task;
  std::string node;
  std::string skill;
};

/// A revision ready to run: its record (already in the history) and its validated, CAD-derived cell.
struct RunningCell {
  CellRevisionRecord record;
  cell::CellFile cell;
  std::filesystem::path model_dir;  ///< where its model paths resolve (cell::resolve_models)
};

/// What a request did. `reply` lacks client_id and request_id (the node fills them). `revision` is set
/// when a new revision was made and must now be applied and published.
struct CellOutcome {
  world_protocol::CellReply reply;
  std::optional<RunningCell> revision;
};

class CellKeeper {
 public:
  struct Settings {
    std::filesystem::path cell_file;       ///< the configured cell file
    std::filesystem::path history_folder;  ///< "" keeps the history in memory only
    std::size_t max_revisions = 100;
  };

  /// Starts as the file comment says. @throws cell::CellFileError for a cell file (or stored revision)
  /// that breaks a rule, CellHistoryError for an unreadable history or a first revision not written.
  CellKeeper(Settings settings, Stamp now);

  /// The running revision.
  const RunningCell& running() const { return running_; }
  /// Whether the start made a new revision (else it came back on the history's).
  bool started_new() const { return started_new_; }
  const CellHistory& history() const { return history_; }

  /// Answers one request (bounds, op, document, rules, held resources). Never throws.
  CellOutcome handle(const world_protocol::CellRequest& request, const std::vector<HeldResource>& held, Stamp now);

  /// The models the running revision pins, with their bytes, for rigger/world/cell_model. A model that
  /// cannot be read any more is left out and named in `problems`. The ones in `published` (by sha256) are
  /// listed without their bytes, which are not read again.
  std::vector<world_protocol::CellModel> pinned_models(std::vector<std::string>* problems = nullptr,
                                                       const std::set<std::string>& published = {}) const;

 private:
  CellOutcome propose(const std::string& text, const world_protocol::CellRequest& request,
                      const std::vector<HeldResource>& held, Stamp now);
  /// The rules, the models resolved (cell folder, then the store), the CAD derivation, the store built.
  /// @throws cell::CellFileError, naming a pinned model nobody sent at its model's pointer.
  RunningCell validated(const std::string& text, Stamp now) const;
  /// Stores the request's models; "" or why they are refused. `added`: the ones new to the store.
  std::string store_models(const world_protocol::CellRequest& request, const nlohmann::json& doc,
                           std::vector<std::string>& added);
  CellOutcome show(std::uint64_t revision) const;
  CellOutcome list() const;
  world_protocol::CellReply reply(bool ok, const char* code, std::string message,
                                  nlohmann::json result = nullptr) const;

  Settings settings_;
  std::string cell_file_;  ///< absolute, as the records name it
  cell::ModelStore models_;          ///< models uploaded with revisions, by sha256
  std::filesystem::path links_root_;  ///< folders of links for revisions that read from the store
  CellHistory history_;
  RunningCell running_;
  nlohmann::json running_doc_;
  bool started_new_ = false;
};

}  // namespace rigger::world
