#pragma once
/// @file
/// Persistence of the world model in SQLite: every accepted change is saved (a change log plus the
/// latest state of each changed entity) so that a restarted world model keeps its entities. Restored
/// poses are never fresh: they come back with localized=false and stale=true, keeping the last pose
/// and stamp, until a new observation arrives (WorldStore::restore_stale applies a PersistedWorld).
///
/// Thread safety: a WorldDatabase is used by one thread at a time.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "world_store.hpp"

struct sqlite3;

namespace rigger::world {

/// The database cannot be opened or read: not a SQLite file, corrupted, another application's
/// database, another schema version, or a malformed row. `what()` names the file.
class PersistenceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The outcome of saving one change (steady state: no exceptions).
struct SaveResult {
  bool ok = true;
  std::string error;  ///< the SQLite error, naming the file, when !ok
};

/// Tuning of a WorldDatabase.
struct WorldDatabaseOptions {
  /// The change log keeps at least this many of the newest changes; older ones are pruned
  /// (the latest state of every entity is always kept).
  std::size_t max_change_log_rows = 100000;
};

/// The SQLite file holding the world model's state. Move-only; closes the file on destruction.
class WorldDatabase {
 public:
  /// Opens the database at `path`, creating it (and its schema) when the file does not exist or is
  /// empty. Checks integrity (PRAGMA quick_check), the application id and the schema version.
  /// @throws PersistenceError naming the file and the problem.
  static WorldDatabase open(const std::filesystem::path& path, WorldDatabaseOptions options = {});

  WorldDatabase(WorldDatabase&& other) noexcept;
  WorldDatabase& operator=(WorldDatabase&& other) noexcept;
  WorldDatabase(const WorldDatabase&) = delete;
  WorldDatabase& operator=(const WorldDatabase&) = delete;
  ~WorldDatabase();

  /// Saves one accepted change (change log row + the entity's latest state) in one transaction.
  /// Never throws; a failure is reported in the result and leaves the database as it was.
  SaveResult save(const ChangeRecord& change) noexcept;

  /// Reads the latest state of every saved entity.
  /// @throws PersistenceError on a read error or a malformed row (naming the entity).
  PersistedWorld load() const;

  /// Rows in the change log (for tests and diagnostics).
  /// @throws PersistenceError on a read error.
  std::size_t change_log_size() const;

  /// The database file.
  const std::filesystem::path& path() const { return path_; }

 private:
  WorldDatabase(std::filesystem::path path, sqlite3* db, WorldDatabaseOptions options);

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
  WorldDatabaseOptions options_;
  std::size_t saves_since_prune_ = 0;
};

}  // namespace rigger::world
