// The world model node's cell revisions: requests, the runs that hold objects, applying and publishing a
// revision (world_model_node.hpp; the decisions are CellKeeper's).
#include "rigger/cell_config/cell_diff.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "world_model_node.hpp"

namespace rigger::world {

std::vector<HeldResource> WorldModelNode::held_resources() const {
  std::vector<HeldResource> all;
  for (const auto& [executor, held] : held_) all.insert(all.end(), held.begin(), held.end());
  return all;
}

void WorldModelNode::on_executors() {
  executors_.take(
      [this](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t& info) {
        const std::string id = dds::to_string(a.executor_id);
        if (info.instance_state != DDS_IST_ALIVE) {
          held_.erase(id);
          return;
        }
        std::vector<HeldResource> held;
        for (const skill_protocol::AnnouncedRun& run : skill_protocol::runs_of(a))
          for (const std::string& resource : run.resources)
            held.push_back({resource, id, run.task_id, run.node_id, run.skill});
        held_[id] = std::move(held);
      },
      [this](const rigger_skill_ExecutorAnnouncement& key, const dds_sample_info_t&) {
        // Gone (disposed, or its liveliness lease expired): its runs hold nothing any more.
        held_.erase(dds::to_string(key.executor_id));
      });
}

void WorldModelNode::on_cell_requests() {
  cell_requests_.take([this](const rigger_world_CellRequest& wire, const dds_sample_info_t&) {
    const world_protocol::CellRequest request = world_protocol::from_wire(wire);
    CellOutcome outcome = keeper_.handle(request, held_resources(), std::chrono::system_clock::now());
    const std::string op = request.op ? std::string(world_protocol::to_string(*request.op)) : "unknown";
    if (outcome.reply.ok) {
      ctx_.log->info("cell request client={} request_id={} op={} who=\"{}\" code={} {}", request.client_id,
                     request.request_id, op, request.who, outcome.reply.code, outcome.reply.message);
    } else {
      ctx_.log->warn("cell request refused client={} request_id={} op={} who=\"{}\" code={} reason=\"{}\"",
                     request.client_id, request.request_id, op, request.who, outcome.reply.code, outcome.reply.message);
    }
    if (outcome.revision) apply_revision(*outcome.revision);
    world_protocol::CellReply& reply = outcome.reply;
    reply.client_id = request.client_id;
    reply.request_id = request.request_id;
    rigger_world_CellReply out{};
    world_protocol::to_wire(reply, out);
    const dds_return_t rc = cell_replies_.write(out);
    if (rc != DDS_RETCODE_OK) ctx_.log->error("cell reply write failed client={} rc={}", request.client_id, rc);
  });
}

void WorldModelNode::apply_revision(const RunningCell& revision) {
  const CellRevisionRecord& r = revision.record;
  std::set<std::string> changed;
  for (const auto& item : r.changes.value("changed", nlohmann::json::array())) changed.insert(item.at("id"));
  const std::vector<ChangeRecord> records = store_.apply_revision(
      revision.cell, cell::moved_entities(r.changes), changed, r.stamp, "cell:" + (r.who.empty() ? "unknown" : r.who));
  for (const ChangeRecord& change : records) {
    revisions_[change.entity_id] = change.revision;
    if (db_) {
      const SaveResult saved = db_->save(change);
      if (!saved.ok) ctx_.log->error("saving change failed revision={} error={}", change.revision, saved.error);
    }
    if (store_.find(change.entity_id) != nullptr) {
      publish_entity(change.after);
    } else {
      rigger_world_EntityState key{};
      key.entity_id = dds::wire_string(change.entity_id);
      entities_.dispose(key);
      revisions_.erase(change.entity_id);
    }
    publish_change(change);
  }
  ctx_.log->info("cell revision applied revision={} previous={} who=\"{}\" comment=\"{}\" changes=\"{}\"", r.revision,
                 r.previous_revision, r.who, r.comment, cell::summarize_changes(r.changes));
  publish_cell();
}

void WorldModelNode::publish_models() {
  // Before the revision that pins them, so that a follower missing one mostly has it when the revision comes.
  std::vector<std::string> problems;
  // Those published already are still pinned but neither read nor written again.
  const std::vector<world_protocol::CellModel> models = keeper_.pinned_models(&problems, published_models_);
  for (const std::string& problem : problems) ctx_.log->error("cell model not published: {}", problem);
  std::set<std::string> now;
  for (const world_protocol::CellModel& m : models) {
    now.insert(m.sha256);
    if (published_models_.count(m.sha256) != 0) continue;
    rigger_world_CellModel wire{};
    world_protocol::to_wire(m, wire);
    const dds_return_t rc = cell_models_.write(wire);
    if (rc != DDS_RETCODE_OK) {
      ctx_.log->error("cell model publish failed model={} sha256={} rc={}", m.name, m.sha256, rc);
      now.erase(m.sha256);
      continue;
    }
    ctx_.log->info("cell model published model={} sha256={} bytes={}", m.name, m.sha256, m.step.size());
  }
  for (const std::string& gone : published_models_) {
    if (now.count(gone) != 0) continue;
    rigger_world_CellModel key{};
    key.sha256 = dds::wire_string(gone);
    cell_models_.dispose(key);
  }
  published_models_ = std::move(now);
}

void WorldModelNode::publish_cell() {
  publish_models();
  const CellRevisionRecord& r = keeper_.running().record;
  world_protocol::CellRevision c;
  c.cell_revision = r.revision;
  c.cell_json = r.cell_json;
  c.sha256 = r.sha256;
  c.previous_revision = r.previous_revision;
  const std::string changes = r.changes.dump();
  c.changes_json = changes;
  c.who = r.who;
  c.comment = r.comment;
  c.stamp = r.stamp;
  rigger_world_CellRevision wire{};
  world_protocol::to_wire(c, wire);
  const dds_return_t rc = cells_.write(wire);
  if (rc != DDS_RETCODE_OK) ctx_.log->error("cell revision publish failed revision={} rc={}", r.revision, rc);
}

}  // namespace rigger::world
