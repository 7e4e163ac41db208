#pragma once
/// @file
/// The world_model process's DDS node: owns the WorldStore and its SQLite database, publishes every
/// entity on `rigger/world/entity` (state QoS: late joiners see the world at once) at start and on
/// each accepted change, publishes who changed what on `rigger/world/change`, answers updates on
/// `rigger/world/update_result` and queries on `rigger/world/reply`. Bad samples are answered with a
/// reason and change nothing; nothing a peer sends can crash it.
///
/// Cell revisions (cell_keeper.hpp): it publishes the running revision on `rigger/world/cell` (state QoS),
/// answers `rigger/world/cell_request` on `rigger/world/cell_reply`, and follows the runs the executors
/// announce on `rigger/skill/executors` to refuse a revision touching what a running skill holds. A new
/// revision is applied to the store, saved and published entity by entity, then as a whole. Validating
/// one (the CAD derivation reads STEP models in a child process) takes the loop for its duration.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cell_keeper.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/service/service.hpp"
#include "rigger/world_model/settings.hpp"
#include "update_memory.hpp"
#include "wire_decoding.hpp"
#include "world_answers.hpp"
#include "world_persistence.hpp"
#include "world_store.hpp"

namespace rigger::world {

/// The default database file.
inline constexpr const char* kDefaultDatabase = "/tmp/rigger/world_model.sqlite";

/// Settings of the node, from the --config file (the keys of world_model_settings()) and the command
/// line (which wins: --cell is taken as it is given).
struct WorldModelSettings {
  std::string cell_config;  ///< the cell file
  std::string database;     ///< the SQLite file (its folder is created); "" keeps no state across restarts
  std::size_t max_change_log_rows{};
  bool follow_tracker{};  ///< apply `rigger/tracker/pose` samples as updates
  /// The cell revisions' folder; "" puts it next to the database ("<database>.cells"), or keeps the
  /// history in memory when the database is "" too.
  std::string cell_history;
  std::size_t max_cell_revisions{};
};

/// Reads the settings from `config` (and calls config.finish()). @throws ConfigError.
WorldModelSettings read_settings(const Config& config);

/// The world model node (see the file comment). Loop thread only.
class WorldModelNode : public service::Node {
 public:
  /// Loads the cell configuration, opens the database and restores its state as stale, then
  /// publishes every entity. @throws ConfigError for a bad cell file (exit 2), PersistenceError for
  /// an unusable database (exit 1).
  WorldModelNode(service::ServiceContext& ctx, const WorldModelSettings& settings);

  const WorldStore& store() const { return store_; }

 private:
  void on_cell_requests();
  void on_executors();
  /// Applies a revision the keeper made to the store; saves and publishes each change, then the revision.
  void apply_revision(const RunningCell& revision);
  void publish_cell();
  void publish_models();  ///< rigger/world/cell_model: the running revision's pinned models, the others disposed
  std::vector<HeldResource> held_resources() const;
  void on_updates();
  void on_queries();
  void on_tracker_poses();
  /// Applies a decoded update; saves, publishes and returns the verdict.
  UpdateResult apply(const EntityUpdate& update);
  void publish_entity(const Entity& entity);
  void publish_change(const ChangeRecord& change);
  void send_update_result(const std::string& source, std::uint64_t seq, const std::string& entity_id, bool accepted,
                          const std::string& code, const std::string& reason, std::uint64_t revision);
  /// Writes a result (one remembered for a repeated update as it is).
  void send_update_result(const world_protocol::UpdateResult& result);
  void send_reply(const std::string& client_id, std::uint64_t request_id, const QueryAnswer& answer);

  service::ServiceContext& ctx_;
  CellKeeper keeper_;
  WorldStore store_;
  std::optional<WorldDatabase> db_;
  std::map<std::string, std::uint64_t, std::less<>> revisions_;  // entity id -> revision of its last change
  UpdateMemory update_memory_;  // results of the last updates, for senders that ask again
  dds::Writer<rigger_world_EntityState> entities_;
  dds::Writer<rigger_world_EntityChange> changes_;
  dds::Writer<rigger_world_UpdateResult> update_results_;
  dds::Writer<rigger_world_WorldReply> replies_;
  dds::Reader<rigger_world_EntityUpdate> updates_;
  dds::Reader<rigger_world_WorldQuery> queries_;
  std::optional<dds::Reader<rigger_vision_TrackedPose>> tracker_poses_;
  dds::Writer<rigger_world_CellRevision> cells_;
  dds::Writer<rigger_world_CellModel> cell_models_;
  std::set<std::string> published_models_;  ///< sha256 of the rigger/world/cell_model instances alive
  dds::Writer<rigger_world_CellReply> cell_replies_;
  dds::Reader<rigger_world_CellRequest> cell_requests_;
  dds::Reader<rigger_skill_ExecutorAnnouncement> executors_;
  std::map<std::string, std::vector<HeldResource>> held_;  ///< by executor id: what its runs hold
};

}  // namespace rigger::world
