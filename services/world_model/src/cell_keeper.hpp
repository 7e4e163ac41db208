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
/// derivation from the STEP models in the configured cell file's folder, the store built from it), then
/// the diff against the running revision and the held resources: all or nothing, and nothing changes on
/// a refusal.
///
/// Thread safety: none; the world model's loop thread owns it.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cell_history.hpp"
#include "rigger/cell_config/cell_file.hpp"
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

 private:
  CellOutcome propose(const std::string& text, const world_protocol::CellRequest& request,
                      const std::vector<HeldResource>& held, Stamp now);
  CellOutcome show(std::uint64_t revision) const;
  CellOutcome list() const;
  world_protocol::CellReply reply(bool ok, const char* code, std::string message,
                                  nlohmann::json result = nullptr) const;

  Settings settings_;
  std::string cell_file_;  ///< absolute, as the records name it
  CellHistory history_;
  RunningCell running_;
  nlohmann::json running_doc_;
  bool started_new_ = false;
};

}  // namespace rigger::world
