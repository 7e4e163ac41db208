#include "dds_cell_requests.hpp"

#include <vector>

#include "rigger/protocol/world.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::skill_sdk {

namespace {

constexpr std::chrono::milliseconds kResendPeriod{500};

nlohmann::json result_of(const world_protocol::CellReply& reply) {
  if (reply.result_json.empty()) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(reply.result_json);
  } catch (const nlohmann::json::exception&) {
    return nlohmann::json::object();
  }
}

OpResult failure_of(const std::optional<world_protocol::CellReply>& reply) {
  if (!reply) return OpResult::failure(world_client::kUnreachable, "the world model did not answer the cell request");
  return OpResult::failure(reply->code, reply->message);
}

}  // namespace

DdsCellRequests::DdsCellRequests(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                 std::string client_id)
    : participant_(participant), loop_(loop), log_(std::move(log)), client_id_(std::move(client_id)) {}

DdsCellRequests::~DdsCellRequests() {
  for (auto& [id, p] : pending_) {
    if (p.deadline != 0) loop_.cancel(p.deadline);
    if (p.again != 0) loop_.cancel(p.again);
  }
}

void DdsCellRequests::open() {
  if (requests_) return;
  requests_.emplace(participant_, protocol::world::kCellRequest);
  replies_.emplace(participant_, protocol::world::kCellReply);
  loop_.on_data(*replies_, [this] {
    replies_->take([this](const rigger_world_CellReply& wire, const dds_sample_info_t&) {
      world_protocol::CellReply reply = world_protocol::from_wire(wire);
      if (reply.client_id != client_id_) return;
      const OpId id = reply.request_id | kIdBit;
      if (pending_.count(id) != 0) finish(id, reply);
    });
  });
}

OpId DdsCellRequests::ask(world_protocol::CellRequest request, bool resend, std::chrono::nanoseconds timeout,
                          Answer done) {
  open();
  const OpId id = ++next_ | kIdBit;
  request.client_id = client_id_;
  request.request_id = id & ~kIdBit;
  Pending& p = pending_[id];
  p.request = std::move(request);
  p.resend = resend;
  p.done = std::move(done);
  p.deadline = loop_.after(timeout, [this, id] {
    pending_[id].deadline = 0;
    finish(id, std::nullopt);
  });
  send(id);
  return id;
}

void DdsCellRequests::send(OpId id) {
  Pending& p = pending_.at(id);
  rigger_world_CellRequest wire{};
  std::vector<rigger_world_CellModel> models;
  world_protocol::to_wire(p.request, wire, models);
  if (const dds_return_t rc = requests_->write(wire); rc != DDS_RETCODE_OK)
    log_->warn("cell request write failed request_id={} rc={}", p.request.request_id, dds_strretcode(rc));
  if (!p.resend) return;
  p.again = loop_.after(kResendPeriod, [this, id] {
    pending_[id].again = 0;
    send(id);
  });
}

void DdsCellRequests::finish(OpId id, const std::optional<world_protocol::CellReply>& reply) {
  auto it = pending_.find(id);
  if (it == pending_.end()) return;
  if (it->second.deadline != 0) loop_.cancel(it->second.deadline);
  if (it->second.again != 0) loop_.cancel(it->second.again);
  Answer done = std::move(it->second.done);
  pending_.erase(it);
  done(reply);
}

void DdsCellRequests::cancel(OpId id) {
  auto it = pending_.find(id);
  if (it == pending_.end()) return;
  if (it->second.deadline != 0) loop_.cancel(it->second.deadline);
  if (it->second.again != 0) loop_.cancel(it->second.again);
  pending_.erase(it);
}

OpId DdsCellRequests::running_cell(std::chrono::nanoseconds timeout,
                                   std::function<void(const OpResult&, const CellDocument&)> done) {
  world_protocol::CellRequest request;
  request.op = world_protocol::CellOp::kShow;
  return ask(std::move(request), true, timeout,
             [done = std::move(done)](const std::optional<world_protocol::CellReply>& reply) {
               if (!reply || !reply->ok) {
                 done(failure_of(reply), {});
                 return;
               }
               const nlohmann::json shown = result_of(*reply);
               CellDocument document;
               document.revision = shown.value("cell_revision", reply->cell_revision);
               document.cell_json = shown.value("cell_json", "");
               if (document.cell_json.empty()) {
                 done(OpResult::failure("WORLD_UPDATE_REJECTED", "the world model showed no cell document"), {});
                 return;
               }
               done(OpResult::success(), document);
             });
}

OpId DdsCellRequests::propose_cell(const CellProposal& proposal, std::chrono::nanoseconds timeout,
                                   std::function<void(const OpResult&, const CellProposalAnswer&)> done) {
  world_protocol::CellRequest request;
  request.op = world_protocol::CellOp::kApply;
  request.cell_json = proposal.cell_json;
  request.who = proposal.who;
  request.comment = proposal.comment;
  request.dry_run = proposal.dry_run;
  return ask(std::move(request), false, timeout,
             [done = std::move(done)](const std::optional<world_protocol::CellReply>& reply) {
               if (!reply || !reply->ok) {
                 done(failure_of(reply), {});
                 return;
               }
               CellProposalAnswer answer;
               answer.revision = reply->cell_revision;
               answer.changes = result_of(*reply).value("changes", nlohmann::json::object());
               done(OpResult::success(reply->message), answer);
             });
}

}  // namespace rigger::skill_sdk
