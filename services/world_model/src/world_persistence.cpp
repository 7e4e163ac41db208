#include "world_persistence.hpp"

#include <cmath>
#include <utility>

#include <sqlite3.h>

#include "rigger/base/bounded_json.hpp"
#include "world_json.hpp"

namespace rigger::world {
namespace {

using nlohmann::json;

// 'RIGW' in the SQLite header marks the file as a rigger world-model database.
constexpr int kApplicationId = 0x52494757;
constexpr int kSchemaVersion = 1;
constexpr std::size_t kPruneEvery = 256;

constexpr const char* kSchema = R"sql(
CREATE TABLE entity_state (
  entity_id  TEXT PRIMARY KEY NOT NULL,
  revision   INTEGER NOT NULL,
  state_json TEXT NOT NULL
);
CREATE TABLE change_log (
  revision   INTEGER PRIMARY KEY NOT NULL,
  entity_id  TEXT NOT NULL,
  source     TEXT NOT NULL,
  stamp_ns   INTEGER NOT NULL,
  what       TEXT NOT NULL,
  state_json TEXT NOT NULL
);
)sql";

class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK) statement_ = nullptr;
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool valid() const { return statement_ != nullptr; }
  sqlite3_stmt* get() const { return statement_; }
  bool bind_text(int index, const std::string& text) {
    return sqlite3_bind_text(statement_, index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT) == SQLITE_OK;
  }
  bool bind_int64(int index, std::int64_t value) { return sqlite3_bind_int64(statement_, index, value) == SQLITE_OK; }
  std::string error() const { return sqlite3_errmsg(db_); }

 private:
  sqlite3* db_;
  sqlite3_stmt* statement_ = nullptr;
};

std::string db_error(const std::filesystem::path& path, sqlite3* db, const std::string& doing) {
  return "world state database " + path.string() + ": " + doing + ": " + sqlite3_errmsg(db) + " (" +
         sqlite3_errstr(sqlite3_extended_errcode(db)) + ")";
}

// Executes SQL without results; false on error.
bool exec(sqlite3* db, const char* sql) { return sqlite3_exec(db, sql, nullptr, nullptr, nullptr) == SQLITE_OK; }

std::int64_t query_int(const std::filesystem::path& path, sqlite3* db, const char* sql) {
  Statement statement(db, sql);
  if (!statement.valid()) throw PersistenceError(db_error(path, db, std::string("reading (") + sql + ")"));
  const int step = sqlite3_step(statement.get());
  if (step == SQLITE_ROW) return sqlite3_column_int64(statement.get(), 0);
  if (step == SQLITE_DONE) return 0;
  throw PersistenceError(db_error(path, db, std::string("reading (") + sql + ")"));
}

std::string column_text(sqlite3_stmt* statement, int column) {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(statement, column));
  return text == nullptr ? std::string() : std::string(text, static_cast<std::size_t>(sqlite3_column_bytes(statement, column)));
}

// Reads the dynamic state saved by save() (the form of entity_to_json).
Entity entity_from_state_json(const json& state) {
  auto field = [&](const char* key) -> const json& {
    const auto it = state.find(key);
    if (it == state.end()) throw std::invalid_argument(std::string("missing \"") + key + "\"");
    return *it;
  };
  auto stamp = [&](const char* key) {
    const json& value = field(key);
    if (!value.is_number_integer()) throw std::invalid_argument(std::string("\"") + key + "\" is not an integer");
    return from_unix_ns(value.get<std::int64_t>());
  };
  auto text = [&](const char* key) {
    const json& value = field(key);
    if (!value.is_string()) throw std::invalid_argument(std::string("\"") + key + "\" is not a string");
    return value.get<std::string>();
  };
  Entity entity;
  entity.id = text("id");
  const auto kind = entity_kind_from_string(text("kind"));
  if (!kind) throw std::invalid_argument("\"kind\" is not object, device or frame");
  entity.kind = *kind;
  entity.parent = text("parent");
  if (!field("localized").is_boolean()) throw std::invalid_argument("\"localized\" is not a boolean");
  entity.localized = field("localized").get<bool>();
  entity.stamp = stamp("stamp_ns");
  entity.source = text("source");
  entity.attributes = field("attributes");
  if (!entity.attributes.is_object()) throw std::invalid_argument("\"attributes\" is not an object");
  if (state.contains("pose")) {
    PoseEstimate estimate;
    estimate.pose_parent_entity = pose_from_json(state.at("pose"));
    estimate.stamp = stamp("pose_stamp_ns");
    estimate.source = text("pose_source");
    if (state.contains("covariance")) {
      const json& values = state.at("covariance");
      if (!values.is_array() || values.size() != 36) throw std::invalid_argument("\"covariance\" is not 36 numbers");
      Covariance6d covariance;
      for (int i = 0; i < 36; ++i) {
        if (!values[static_cast<std::size_t>(i)].is_number()) throw std::invalid_argument("\"covariance\" is not 36 numbers");
        covariance(i / 6, i % 6) = values[static_cast<std::size_t>(i)].get<double>();
      }
      estimate.covariance = covariance;
    }
    if (state.contains("quality")) {
      if (!state.at("quality").is_number()) throw std::invalid_argument("\"quality\" is not a number");
      estimate.quality = state.at("quality").get<double>();
    }
    entity.pose = estimate;
  }
  return entity;
}

}  // namespace

WorldDatabase WorldDatabase::open(const std::filesystem::path& path, WorldDatabaseOptions options) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  // From here on the handle belongs to `db`, whose destructor closes it on every error path.
  WorldDatabase db(path, raw, options);
  if (rc != SQLITE_OK) {
    throw PersistenceError(raw != nullptr ? db_error(path, raw, "opening")
                                          : "world state database " + path.string() + ": cannot open (out of memory)");
  }
  sqlite3_extended_result_codes(raw, 1);
  sqlite3_busy_timeout(raw, 2000);

  // A file that is not SQLite fails here with SQLITE_NOTADB; a damaged one fails the integrity check.
  {
    Statement check(raw, "PRAGMA quick_check");
    if (!check.valid()) throw PersistenceError(db_error(path, raw, "checking integrity"));
    const int step = sqlite3_step(check.get());
    if (step != SQLITE_ROW) throw PersistenceError(db_error(path, raw, "checking integrity"));
    const std::string verdict = column_text(check.get(), 0);
    if (verdict != "ok") {
      throw PersistenceError("world state database " + path.string() + ": integrity check failed: " + verdict);
    }
  }
  const std::int64_t application_id = query_int(path, raw, "PRAGMA application_id");
  const std::int64_t schema_version = query_int(path, raw, "PRAGMA user_version");
  const std::int64_t tables = query_int(path, raw, "SELECT count(*) FROM sqlite_master");
  if (application_id == 0 && schema_version == 0 && tables == 0) {
    const std::string create = std::string("BEGIN;") + kSchema + "PRAGMA application_id = " +
                               std::to_string(kApplicationId) + "; PRAGMA user_version = " +
                               std::to_string(kSchemaVersion) + "; COMMIT;";
    if (!exec(raw, create.c_str())) {
      const std::string error = db_error(path, raw, "creating the schema");
      exec(raw, "ROLLBACK");
      throw PersistenceError(error);
    }
  } else if (application_id != kApplicationId) {
    throw PersistenceError("world state database " + path.string() +
                           ": not a rigger world-model database (SQLite application_id " + std::to_string(application_id) +
                           ", expected " + std::to_string(kApplicationId) + ")");
  } else if (schema_version != kSchemaVersion) {
    throw PersistenceError("world state database " + path.string() + ": schema version " + std::to_string(schema_version) +
                           ", this world model reads version " + std::to_string(kSchemaVersion));
  }
  // WAL with synchronous=NORMAL: a change costs no fsync, and a crash loses at most the last few
  // changes, never the database's consistency.
  if (!exec(raw, "PRAGMA journal_mode = WAL; PRAGMA synchronous = NORMAL;")) {
    throw PersistenceError(db_error(path, raw, "setting the journal mode"));
  }
  return db;
}

WorldDatabase::WorldDatabase(std::filesystem::path path, sqlite3* db, WorldDatabaseOptions options)
    : path_(std::move(path)), db_(db), options_(options) {}

WorldDatabase::WorldDatabase(WorldDatabase&& other) noexcept
    : path_(std::move(other.path_)),
      db_(std::exchange(other.db_, nullptr)),
      options_(other.options_),
      saves_since_prune_(other.saves_since_prune_) {}

WorldDatabase& WorldDatabase::operator=(WorldDatabase&& other) noexcept {
  if (this != &other) {
    sqlite3_close_v2(db_);
    path_ = std::move(other.path_);
    db_ = std::exchange(other.db_, nullptr);
    options_ = other.options_;
    saves_since_prune_ = other.saves_since_prune_;
  }
  return *this;
}

WorldDatabase::~WorldDatabase() { sqlite3_close_v2(db_); }

SaveResult WorldDatabase::save(const ChangeRecord& change) noexcept {
  try {
    // Strings from the wire may hold invalid UTF-8; replace rather than fail the save.
    const std::string state = entity_to_json(change.after).dump(-1, ' ', false, json::error_handler_t::replace);
    if (!exec(db_, "BEGIN IMMEDIATE")) return {false, db_error(path_, db_, "beginning a transaction")};
    Statement log(db_,
                  "INSERT OR REPLACE INTO change_log (revision, entity_id, source, stamp_ns, what, state_json) "
                  "VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    Statement latest(db_, "INSERT OR REPLACE INTO entity_state (entity_id, revision, state_json) VALUES (?1, ?2, ?3)");
    const bool ok = log.valid() && latest.valid() && log.bind_int64(1, static_cast<std::int64_t>(change.revision)) &&
                    log.bind_text(2, change.entity_id) && log.bind_text(3, change.source) &&
                    log.bind_int64(4, to_unix_ns(change.stamp)) && log.bind_text(5, change.what()) &&
                    log.bind_text(6, state) && sqlite3_step(log.get()) == SQLITE_DONE && latest.bind_text(1, change.entity_id) &&
                    latest.bind_int64(2, static_cast<std::int64_t>(change.revision)) && latest.bind_text(3, state) &&
                    sqlite3_step(latest.get()) == SQLITE_DONE;
    if (!ok) {
      const std::string error = db_error(path_, db_, "saving revision " + std::to_string(change.revision));
      exec(db_, "ROLLBACK");
      return {false, error};
    }
    if (++saves_since_prune_ >= kPruneEvery) {
      saves_since_prune_ = 0;
      const std::string prune = "DELETE FROM change_log WHERE revision <= (SELECT max(revision) FROM change_log) - " +
                                std::to_string(options_.max_change_log_rows);
      if (!exec(db_, prune.c_str())) {
        const std::string error = db_error(path_, db_, "pruning the change log");
        exec(db_, "ROLLBACK");
        return {false, error};
      }
    }
    if (!exec(db_, "COMMIT")) {
      const std::string error = db_error(path_, db_, "committing revision " + std::to_string(change.revision));
      exec(db_, "ROLLBACK");
      return {false, error};
    }
    return {};
  } catch (const std::exception& error) {
    exec(db_, "ROLLBACK");
    return {false, "world state database " + path_.string() + ": saving revision " + std::to_string(change.revision) + ": " +
                       error.what()};
  }
}

PersistedWorld WorldDatabase::load() const {
  PersistedWorld world;
  Statement rows(db_, "SELECT entity_id, revision, state_json FROM entity_state ORDER BY revision");
  if (!rows.valid()) throw PersistenceError(db_error(path_, db_, "reading entity states"));
  int step = SQLITE_ROW;
  while ((step = sqlite3_step(rows.get())) == SQLITE_ROW) {
    const std::string id = column_text(rows.get(), 0);
    const auto revision = sqlite3_column_int64(rows.get(), 1);
    const std::string text = column_text(rows.get(), 2);
    try {
      auto parsed = parse_json_bounded(text);
      if (!parsed.ok()) throw std::invalid_argument(parsed.error->to_string());
      Entity entity = entity_from_state_json(parsed.value);
      if (entity.id != id) throw std::invalid_argument("the state names entity \"" + entity.id + "\"");
      world.entities.push_back(std::move(entity));
    } catch (const std::exception& error) {
      throw PersistenceError("world state database " + path_.string() + ": entity_state row \"" + id +
                             "\" is malformed: " + error.what());
    }
    if (revision > 0) world.revision = std::max(world.revision, static_cast<std::uint64_t>(revision));
  }
  if (step != SQLITE_DONE) throw PersistenceError(db_error(path_, db_, "reading entity states"));
  const std::int64_t last_logged = query_int(path_, db_, "SELECT coalesce(max(revision), 0) FROM change_log");
  if (last_logged > 0) world.revision = std::max(world.revision, static_cast<std::uint64_t>(last_logged));
  return world;
}

std::size_t WorldDatabase::change_log_size() const {
  return static_cast<std::size_t>(query_int(path_, db_, "SELECT count(*) FROM change_log"));
}

}  // namespace rigger::world
