#include "world_model_node.hpp"

#include <filesystem>

#include "rigger/base/install.hpp"
#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/cell_config/cell_diff.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "world_cell_config.hpp"
#include "world_json.hpp"

namespace rigger::world {
namespace {

world_protocol::EntityKind protocol_kind(EntityKind kind) {
  switch (kind) {
    case EntityKind::kObject:
      return world_protocol::EntityKind::kObject;
    case EntityKind::kDevice:
      return world_protocol::EntityKind::kDevice;
    case EntityKind::kFrame:
      return world_protocol::EntityKind::kFrame;
  }
  return world_protocol::EntityKind::kFrame;
}

std::string history_folder(const WorldModelSettings& settings) {
  if (!settings.cell_history.empty()) return settings.cell_history;
  return settings.database.empty() ? std::string() : settings.database + ".cells";
}

CellKeeper start_keeper(const WorldModelSettings& settings, const Config& config, const Logger& log) {
  const auto started = std::chrono::steady_clock::now();
  try {
    // The CAD features given by rules over the objects' STEP models are derived here, once, before the
    // store answers: a reference into a changed model stops the start (docs/cad.md).
    CellKeeper keeper({settings.cell_config, history_folder(settings), settings.max_cell_revisions},
                      std::chrono::system_clock::now());
    const CellRevisionRecord& r = keeper.running().record;
    log->info("cell loaded file={} revision={} as=\"{}\" entities={} history={} load_s={:.3f}", settings.cell_config,
              r.revision, keeper.started_new() ? "a new revision of the file" : "the history's latest",
              keeper.running().cell.entities.size(), history_folder(settings),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    return keeper;
  } catch (const CellConfigError& e) {
    throw ConfigError(config.file(), "/cell_config", e.what());
  } catch (const CellHistoryError& e) {
    throw ConfigError(config.file(), "/cell_history", e.what());
  }
}

std::optional<WorldDatabase> open_database(const WorldModelSettings& settings, WorldStore& store, const Logger& log) {
  if (settings.database.empty()) {
    log->warn("persistence off: state will not survive a restart");
    return std::nullopt;
  }
  const std::filesystem::path path(settings.database);
  if (path.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) throw PersistenceError(path.string() + ": cannot create its folder: " + ec.message());
  }
  WorldDatabaseOptions options;
  options.max_change_log_rows = settings.max_change_log_rows;
  WorldDatabase db = WorldDatabase::open(path, options);
  const RestoreReport report = store.restore_stale(db.load());
  log->info("state restored database={} restored={} ignored={} revision={}", path.string(), report.restored.size(),
            report.ignored.size(), store.revision());
  for (const auto& id : report.ignored) log->warn("persisted entity ignored id={} (no longer configured)", id);
  return db;
}

}  // namespace

const SettingsTable<WorldModelSettings>& world_model_settings() {
  using S = WorldModelSettings;
  static const SettingsTable<S> table{
      path_setting<S>("cell_config", kDefaultCellFile, &S::cell_config,
                      "the cell file: relative to this file, then to the data folder; `--cell` takes its place"),
      setting<S>("database", kDefaultDatabase, &S::database,
                 "the SQLite state file (its folder is created); `\"\"` keeps no state across restarts; `--db` "
                 "takes its place"),
      setting<S>("max_change_log_rows", 100000u, {100u, 10000000u}, &S::max_change_log_rows,
                 "change-log rows kept, pruned every 256 saves; the latest states are always kept"),
      setting<S>("follow_tracker", true, &S::follow_tracker, "apply `rigger/tracker/pose` samples as updates"),
      setting<S>("cell_history", "", &S::cell_history,
                 "the folder of the cell revisions (one file each); `\"\"`: `<database>.cells`, or in memory when "
                 "`database` is `\"\"`"),
      setting<S>("max_cell_revisions", 100u, {1u, 100000u}, &S::max_cell_revisions,
                 "cell revisions kept in the history; the oldest go first"),
  };
  return table;
}

WorldModelSettings read_settings(const Config& config) {
  return rigger::read_settings(config, world_model_settings());
}

WorldModelNode::WorldModelNode(service::ServiceContext& ctx, const WorldModelSettings& settings)
    : ctx_(ctx),
      keeper_(start_keeper(settings, ctx.config, ctx.log)),
      store_(WorldStore::from_config(keeper_.running().cell, std::chrono::system_clock::now())),
      db_(open_database(settings, store_, ctx.log)),
      entities_(ctx.participant, protocol::world::kEntity),
      changes_(ctx.participant, protocol::world::kChange),
      update_results_(ctx.participant, protocol::world::kUpdateResult),
      replies_(ctx.participant, protocol::world::kReply),
      updates_(ctx.participant, protocol::world::kUpdate),
      queries_(ctx.participant, protocol::world::kQuery),
      cells_(ctx.participant, protocol::world::kCell),
      cell_models_(ctx.participant, protocol::world::kCellModel),
      cell_replies_(ctx.participant, protocol::world::kCellReply),
      cell_requests_(ctx.participant, protocol::world::kCellRequest),
      executors_(ctx.participant, protocol::skill::kExecutors, dds::qos::state()) {
  for (const auto& [id, entity] : store_.entities()) publish_entity(entity);
  publish_cell();
  ctx.loop.on_data(cell_requests_, [this] { on_cell_requests(); });
  ctx.loop.on_data(executors_, [this] { on_executors(); });
  ctx.loop.on_data(updates_, [this] { on_updates(); });
  ctx.loop.on_data(queries_, [this] { on_queries(); });
  if (settings.follow_tracker) {
    tracker_poses_.emplace(ctx.participant, protocol::vision::kTrackerPose);
    ctx.loop.on_data(*tracker_poses_, [this] { on_tracker_poses(); });
  }
  ctx.log->info("world model ready entities={} revision={} cell_revision={}", store_.entities().size(),
                store_.revision(), keeper_.running().record.revision);
}

void WorldModelNode::on_updates() {
  updates_.take([this](const rigger_world_EntityUpdate& wire, const dds_sample_info_t&) {
    const world_protocol::Update sent = world_protocol::from_wire(wire);
    const std::string& source = sent.source;
    const std::string& entity_id = sent.entity_id;
    if (const world_protocol::UpdateResult* known = update_memory_.find(source, sent.seq)) {
      // Sent again: its sender did not hear the result. Answered as before, not applied twice.
      ctx_.log->debug("update repeated source={} seq={}: answered with its result", source, sent.seq);
      send_update_result(*known);
      return;
    }
    auto decoded = decode_update(sent);
    if (auto* err = std::get_if<DecodeError>(&decoded)) {
      ctx_.log->warn("update refused source={} seq={} code={} reason={}", source, sent.seq, err->code, err->message);
      send_update_result(source, sent.seq, entity_id, false, err->code, err->message, store_.revision());
      return;
    }
    const UpdateResult result = apply(std::get<EntityUpdate>(decoded));
    if (!result.accepted()) {
      const std::string code(to_code(result.status));
      ctx_.log->info("update rejected source={} seq={} entity={} code={} reason={}", source, sent.seq, entity_id, code,
                     result.reason);
      send_update_result(source, sent.seq, entity_id, false, code, result.reason, store_.revision());
      return;
    }
    send_update_result(source, sent.seq, entity_id, true, std::string(to_code(UpdateStatus::kAccepted)), "",
                       result.change->revision);
  });
}

UpdateResult WorldModelNode::apply(const EntityUpdate& update) {
  UpdateResult result = store_.apply(update);
  if (!result.accepted()) return result;
  const ChangeRecord& change = *result.change;
  revisions_[change.entity_id] = change.revision;
  if (db_) {
    const SaveResult saved = db_->save(change);
    if (!saved.ok) ctx_.log->error("saving change failed revision={} error={}", change.revision, saved.error);
  }
  publish_entity(change.after);
  publish_change(change);
  return result;
}

void WorldModelNode::on_tracker_poses() {
  tracker_poses_->take([this](const rigger_vision_TrackedPose& wire, const dds_sample_info_t&) {
    if (!wire.tracked) {
      // A lost object is reported every frame: only the first report changes anything.
      const Entity* e = store_.find(dds::to_string(wire.object_id));
      if (e == nullptr || !e->localized) return;
    }
    auto decoded = decode_tracked_pose(wire);
    if (auto* err = std::get_if<DecodeError>(&decoded)) {
      ctx_.log->debug("tracker pose refused object={} code={} reason={}", dds::to_string(wire.object_id), err->code,
                      err->message);
      return;
    }
    const UpdateResult result = apply(std::get<EntityUpdate>(decoded));
    if (!result.accepted()) {
      // Debug only: at camera rate a late frame (STAMP_BACKWARDS) is normal, not news.
      ctx_.log->debug("tracker pose rejected object={} code={} reason={}", dds::to_string(wire.object_id),
                      to_code(result.status), result.reason);
    }
  });
}

void WorldModelNode::on_queries() {
  queries_.take([this](const rigger_world_WorldQuery& wire, const dds_sample_info_t&) {
    const world_protocol::Query sent = world_protocol::from_wire(wire);
    auto decoded = decode_query(sent);
    if (auto* err = std::get_if<DecodeError>(&decoded)) {
      QueryAnswer answer;
      answer.code = err->code;
      answer.message = err->message;
      send_reply(sent.client_id, sent.request_id, answer);
      return;
    }
    send_reply(sent.client_id, sent.request_id,
               answer_query(store_, std::get<WorldQuery>(decoded), std::chrono::system_clock::now()));
  });
}

void WorldModelNode::publish_entity(const Entity& entity) {
  world_protocol::EntityState s;
  s.entity_id = entity.id;
  s.kind = protocol_kind(entity.kind);
  s.parent_frame = entity.parent;
  if (entity.pose) s.pose_parent_entity = entity.pose->pose_parent_entity;
  if (entity.pose && entity.pose->covariance) s.covariance = *entity.pose->covariance;
  s.quality = entity.pose && entity.pose->quality ? *entity.pose->quality : 0.0;
  s.localized = entity.localized;
  s.stale = entity.stale;
  s.stamp = entity.pose ? entity.pose->stamp : entity.stamp;
  s.source = entity.source;
  s.features_json = features_to_json(entity.features).dump();
  s.attributes_json = entity.attributes.dump();
  const auto rev = revisions_.find(entity.id);
  s.revision = rev == revisions_.end() ? 0 : rev->second;
  rigger_world_EntityState wire{};
  world_protocol::to_wire(s, wire);
  const dds_return_t rc = entities_.write(wire);
  if (rc != DDS_RETCODE_OK) ctx_.log->error("entity publish failed id={} rc={}", entity.id, rc);
}

void WorldModelNode::publish_change(const ChangeRecord& change) {
  const world_protocol::EntityChange c{change.entity_id, change.revision, change.source, change.what(), change.stamp};
  rigger_world_EntityChange wire{};
  world_protocol::to_wire(c, wire);
  changes_.write(wire);
}

void WorldModelNode::send_update_result(const std::string& source, std::uint64_t seq, const std::string& entity_id,
                                        bool accepted, const std::string& code, const std::string& reason,
                                        std::uint64_t revision) {
  const world_protocol::UpdateResult r{source, seq, entity_id, accepted, code, reason, revision};
  update_memory_.remember(r);
  send_update_result(r);
}

void WorldModelNode::send_update_result(const world_protocol::UpdateResult& r) {
  rigger_world_UpdateResult wire{};
  world_protocol::to_wire(r, wire);
  update_results_.write(wire);
}

void WorldModelNode::send_reply(const std::string& client_id, std::uint64_t request_id, const QueryAnswer& answer) {
  world_protocol::Reply r;
  r.client_id = client_id;
  r.request_id = request_id;
  r.ok = answer.ok;
  r.code = answer.code;
  r.message = answer.message;
  r.stamp = answer.stamp;
  r.frame = answer.frame;
  r.pose_frame_entity = answer.pose_frame_entity;
  r.localized = answer.localized;
  r.age_s = answer.age_s;
  r.result_json = answer.result.is_null() ? std::string() : answer.result.dump();
  rigger_world_WorldReply wire{};
  world_protocol::to_wire(r, wire);
  replies_.write(wire);
}

}  // namespace rigger::world
