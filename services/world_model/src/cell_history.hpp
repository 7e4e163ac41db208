#pragma once
/// @file
/// The world model's cell revisions on disk: one JSON file per revision (`revision-<number>.json` in the
/// history folder), each written to a temporary file, flushed and renamed into place, so a crash leaves
/// either the old set or the new one. At most `max_revisions` are kept; the oldest go first (the running
/// revision, the newest, always stays). A folder "" keeps the history in memory only.
///
/// Thread safety: none; the world model's loop thread owns it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "world_types.hpp"

namespace rigger::world {

/// One revision of the cell.
struct CellRevisionRecord {
  std::uint64_t revision = 0;
  std::uint64_t previous_revision = 0;                ///< 0 for the first
  std::string cell_json;                              ///< the document as submitted (or as the cell file holds it)
  std::string sha256;                                 ///< of cell_json
  std::string cell_file;                              ///< the configured cell file it is a revision of (absolute)
  std::string file_sha256;                            ///< of that file's bytes when this revision was made
  nlohmann::json changes = nlohmann::json::object();  ///< against previous_revision (cell_changes.hpp)
  std::string who;
  std::string comment;
  Stamp stamp{};
};

/// A history file that cannot be read: names it and what is wrong.
class CellHistoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CellHistory {
 public:
  /// Reads every revision file of `folder` (created when missing). @throws CellHistoryError for a folder
  /// that cannot be created or read or a revision file that does not parse.
  CellHistory(std::filesystem::path folder, std::size_t max_revisions);

  /// All kept revisions, oldest first.
  const std::vector<CellRevisionRecord>& revisions() const { return revisions_; }
  /// The revision with this number, or nullptr (never made, or pruned).
  const CellRevisionRecord* find(std::uint64_t revision) const;
  /// The newest revision of `cell_file`, or nullptr.
  const CellRevisionRecord* latest_of(const std::string& cell_file) const;
  /// The number the next revision gets: one more than the highest ever kept.
  std::uint64_t next_revision() const;

  /// Writes `record` (its number must be next_revision()) and prunes. Returns "" or what failed (the
  /// history in memory is then unchanged).
  std::string append(CellRevisionRecord record);

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
  std::size_t max_revisions_;
  std::vector<CellRevisionRecord> revisions_;
};

/// The record as its file holds it, and back. from_json @throws nlohmann::json::exception.
nlohmann::json to_json(const CellRevisionRecord& record);
CellRevisionRecord record_from_json(const nlohmann::json& j);

}  // namespace rigger::world
