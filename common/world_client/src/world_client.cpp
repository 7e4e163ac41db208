#include "rigger/world_client/world_client.hpp"

#include <memory>
#include <utility>

#include "rigger/base/bounded_json.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::world_client {
namespace {

world_protocol::Query query_of(world_protocol::QueryKind kind, const std::string& entity, const std::string& frame,
                               const std::string& feature, double max_age_s) {
  world_protocol::Query q;
  q.kind = kind;
  q.entity_id = entity;
  q.frame_id = frame;
  q.feature_id = feature;
  q.max_age_s = max_age_s;
  return q;
}

}  // namespace

WorldClient::WorldClient(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string client_id)
    : loop_(loop),
      log_(std::move(log)),
      client_id_(std::move(client_id)),
      queries_(participant, protocol::world::kQuery),
      replies_(participant, protocol::world::kReply),
      updates_(participant, protocol::world::kUpdate),
      update_results_(participant, protocol::world::kUpdateResult) {
  loop_.on_data(replies_, [this] { on_replies(); });
  loop_.on_data(update_results_, [this] { on_update_results(); });
}

WorldClient::~WorldClient() {
  for (auto& [id, p] : pending_) {
    loop_.cancel(p.timer);
    loop_.cancel(p.retry);
  }
}

bool WorldClient::connected() const {
  return queries_.matched_readers() > 0 && replies_.matched_writers() > 0;
}

std::uint64_t WorldClient::is_localized(const std::string& entity, double max_age_s, std::chrono::milliseconds timeout,
                                        Callback cb) {
  return send_query(query_of(world_protocol::QueryKind::kIsLocalized, entity, "", "", max_age_s), timeout,
                    std::move(cb));
}

std::uint64_t WorldClient::pose(const std::string& entity, const std::string& frame, std::chrono::milliseconds timeout,
                                Callback cb) {
  return send_query(query_of(world_protocol::QueryKind::kPose, entity, frame, "", 0.0), timeout, std::move(cb));
}

std::uint64_t WorldClient::feature_pose(const std::string& entity, const std::string& feature_id,
                                        const std::string& frame, std::chrono::milliseconds timeout, Callback cb) {
  return send_query(query_of(world_protocol::QueryKind::kPose, entity, frame, feature_id, 0.0), timeout, std::move(cb));
}

std::uint64_t WorldClient::features(const std::string& entity, std::chrono::milliseconds timeout, Callback cb) {
  return send_query(query_of(world_protocol::QueryKind::kFeatures, entity, "", "", 0.0), timeout, std::move(cb));
}

std::uint64_t WorldClient::entity(const std::string& entity, std::chrono::milliseconds timeout, Callback cb) {
  return send_query(query_of(world_protocol::QueryKind::kEntity, entity, "", "", 0.0), timeout, std::move(cb));
}

std::uint64_t WorldClient::list(std::chrono::milliseconds timeout, Callback cb,
                                std::optional<world_protocol::EntityKind> kind) {
  world_protocol::Query q = query_of(world_protocol::QueryKind::kList, "", "", "", 0.0);
  q.list_kind = kind;
  return send_query(std::move(q), timeout, std::move(cb));
}

std::uint64_t WorldClient::update_pose(const std::string& entity, const std::string& parent_frame,
                                       const Eigen::Isometry3d& pose, WallTime stamp, double quality, bool localized,
                                       std::chrono::milliseconds timeout, Callback cb) {
  world_protocol::Update u;
  u.entity_id = entity;
  u.parent_frame = parent_frame;
  u.pose = world_protocol::PoseAsSent{pose.translation(), Eigen::Quaterniond(pose.rotation())};
  if (quality >= 0.0) u.quality = quality;
  u.localized = localized;
  u.stamp = stamp;
  return send_update(std::move(u), timeout, std::move(cb));
}

std::uint64_t WorldClient::set_localized(const std::string& entity, bool localized, WallTime stamp,
                                         std::chrono::milliseconds timeout, Callback cb) {
  world_protocol::Update u;
  u.entity_id = entity;
  u.localized = localized;
  u.stamp = stamp;
  return send_update(std::move(u), timeout, std::move(cb));
}

void WorldClient::cancel(std::uint64_t request_id) {
  auto it = pending_.find(request_id);
  if (it == pending_.end()) return;
  loop_.cancel(it->second.timer);
  loop_.cancel(it->second.retry);
  pending_.erase(it);
}

std::uint64_t WorldClient::track(std::chrono::milliseconds timeout, const char* topic, Callback cb) {
  const std::uint64_t id = next_request_id_++;
  Pending p;
  p.callback = std::move(cb);
  p.timer = loop_.after(timeout, [this, id, timeout, topic] {
    const auto it = pending_.find(id);
    const bool sent = it == pending_.end() || it->second.sent;
    fail_soon(id, sent ? "no reply from the world model within " + std::to_string(timeout.count()) + " ms"
                       : std::string("no world model is matched on ") + topic + " within " +
                             std::to_string(timeout.count()) + " ms");
  });
  pending_.emplace(id, std::move(p));
  return id;
}

std::uint64_t WorldClient::send_query(world_protocol::Query query, std::chrono::milliseconds timeout, Callback cb) {
  const std::uint64_t id = track(timeout, protocol::world::kQuery.name, std::move(cb));
  query.client_id = client_id_;
  query.request_id = id;
  write_query(id, std::make_shared<const world_protocol::Query>(std::move(query)));
  return id;
}

void WorldClient::write_query(std::uint64_t id, std::shared_ptr<const world_protocol::Query> query) {
  auto it = pending_.find(id);
  if (it == pending_.end()) return;  // timed out or cancelled while waiting
  it->second.retry = 0;
  if (!connected()) {
    // Discovery may be a round behind a world model that has just started (or a client that has): wait
    // for the match within the request's own timeout, which then says no world model was matched.
    it->second.retry = loop_.after(std::chrono::milliseconds(20), [this, id, query] { write_query(id, query); });
    return;
  }
  it->second.sent = true;
  rigger_world_WorldQuery q{};
  world_protocol::to_wire(*query, q);
  const dds_return_t rc = queries_.write(q);
  if (rc != DDS_RETCODE_OK) {
    log_->warn("world query write failed request_id={} rc={}", id, rc);
    loop_.post([this, id, rc] { fail_soon(id, "writing the query failed: " + std::string(dds_strretcode(rc))); });
    return;
  }
  // We see the world model before it sees us: a reply it writes before its reply writer has discovered this
  // client is lost (volatile). A query is a read, so it is asked again until answered or timed out; the
  // first answer wins and later ones find nothing pending.
  it->second.retry = loop_.after(kQueryResend, [this, id, query] { write_query(id, query); });
}

std::uint64_t WorldClient::send_update(world_protocol::Update update, std::chrono::milliseconds timeout, Callback cb) {
  const std::uint64_t id = track(timeout, protocol::world::kUpdate.name, std::move(cb));
  update.source = client_id_;
  update.seq = id;
  write_update(id, std::make_shared<const world_protocol::Update>(std::move(update)));
  return id;
}

void WorldClient::write_update(std::uint64_t id, std::shared_ptr<const world_protocol::Update> update) {
  auto it = pending_.find(id);
  if (it == pending_.end()) return;  // timed out or cancelled while waiting
  it->second.retry = 0;
  if (updates_.matched_readers() == 0 || update_results_.matched_writers() == 0) {
    // As for queries: wait for the match within the request's own timeout.
    it->second.retry = loop_.after(std::chrono::milliseconds(20), [this, id, update] { write_update(id, update); });
    return;
  }
  it->second.sent = true;
  rigger_world_EntityUpdate u{};
  world_protocol::to_wire(*update, u);
  const dds_return_t rc = updates_.write(u);
  if (rc != DDS_RETCODE_OK) {
    log_->warn("world update write failed request_id={} rc={}", id, rc);
    loop_.post([this, id, rc] { fail_soon(id, "writing the update failed: " + std::string(dds_strretcode(rc))); });
    return;
  }
  // As for a query, the result may be lost on a world model that has not yet discovered this client: sent
  // again until answered. The world model knows the update by (source, seq) and answers a repeat with the
  // result it had, without applying it twice.
  it->second.retry = loop_.after(kQueryResend, [this, id, update] { write_update(id, update); });
}

void WorldClient::fail_soon(std::uint64_t request_id, const std::string& why) {
  Reply r;
  r.ok = false;
  r.code = kUnreachable;
  r.message = why;
  finish(request_id, r);
}

void WorldClient::finish(std::uint64_t request_id, const Reply& reply) {
  auto it = pending_.find(request_id);
  if (it == pending_.end()) return;  // cancelled, timed out, or a duplicate answer
  loop_.cancel(it->second.timer);
  loop_.cancel(it->second.retry);
  Callback cb = std::move(it->second.callback);
  pending_.erase(it);  // before the callback: it may issue or cancel requests
  if (cb) cb(reply);
}

void WorldClient::on_replies() {
  std::vector<std::pair<std::uint64_t, Reply>> done;
  replies_.take([&](const rigger_world_WorldReply& wire, const dds_sample_info_t&) {
    const world_protocol::Reply w = world_protocol::from_wire(wire);
    if (w.client_id != client_id_ || pending_.count(w.request_id) == 0) return;
    Reply r;
    r.ok = w.ok;
    r.code = w.code;
    r.message = w.message;
    r.localized = w.localized;
    r.age_s = w.age_s;
    if (w.ok) {
      r.pose = w.pose_frame_entity;
      r.frame = w.frame;
    }
    const std::string& text = w.result_json;
    if (!text.empty()) {
      // From another process: parsed with bounds (an entity list or a feature set, not megabytes).
      JsonParseResult parsed = parse_json_bounded(text, {4U * 1024U * 1024U, 64});
      if (parsed.ok()) {
        r.result = std::move(parsed.value);
      } else {
        r = Reply{};
        r.code = kBadReply;
        r.message = "the world model's result_json is not acceptable JSON: " + parsed.error->to_string();
      }
    }
    done.emplace_back(w.request_id, std::move(r));
  });
  // Callbacks run after the take: they may send requests, which must not re-enter the reader.
  for (const auto& [id, r] : done) finish(id, r);
}

void WorldClient::on_update_results() {
  std::vector<std::pair<std::uint64_t, Reply>> done;
  update_results_.take([&](const rigger_world_UpdateResult& wire, const dds_sample_info_t&) {
    const world_protocol::UpdateResult w = world_protocol::from_wire(wire);
    if (w.source != client_id_ || pending_.count(w.seq) == 0) return;
    Reply r;
    r.ok = w.accepted;
    r.code = w.code;
    r.message = w.reason;
    r.result = {{"entity_id", w.entity_id}, {"revision", w.revision}};
    done.emplace_back(w.seq, std::move(r));
  });
  for (const auto& [id, r] : done) finish(id, r);
}

}  // namespace rigger::world_client
