#include "rehearsal_revision.hpp"

#include "rigger/dds/conversions.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::console {

namespace {
std::string seconds_text(std::chrono::milliseconds d) {
  return std::to_string(d.count() / 1000.0).substr(0, 4) + " s";
}
}  // namespace

RehearsalRevision::RehearsalRevision(const dds::Participant& participant, dds::EventLoop& loop, std::string client_id,
                                     std::chrono::milliseconds timeout)
    : loop_(loop),
      requests_(participant, protocol::world::kCellRequest),
      replies_(participant, protocol::world::kCellReply),
      revisions_(participant, protocol::world::kCell),
      states_(participant, protocol::system::kServiceState),
      client_id_(std::move(client_id)),
      timeout_(timeout) {}

RehearsalRevision::~RehearsalRevision() {
  for (auto& [id, p] : pending_) loop_.cancel(p.timer);
}

void RehearsalRevision::bring_to(const CellTarget& target, const std::string& who, Done done) {
  if (target.sha256 == running_sha256_) {
    // The world model runs it already; the simulator may still be refusing it.
    const std::uint64_t id = next_request_++;
    pending_[id] = {target.sha256, target.revision, true, std::move(done), expire_after_timeout(id)};
    return settle();
  }
  if (!world_model()) {
    return done("no world model answers cell requests on the rehearsal domain, so the cell's revision " +
                std::to_string(target.revision) + " cannot be applied there");
  }
  world_protocol::CellRequest q;
  q.op = world_protocol::CellOp::kApply;
  q.cell_json = target.cell_json;
  q.who = who;
  q.comment = "the cell's revision " + std::to_string(target.revision) + ", for a rehearsal";
  q.client_id = client_id_;
  q.request_id = next_request_++;
  q.models = target.models;
  rigger_world_CellRequest wire{};
  std::vector<rigger_world_CellModel> models;
  world_protocol::to_wire(q, wire, models);
  const dds_return_t rc = requests_.write(wire);
  if (rc != DDS_RETCODE_OK) return done(std::string("the cell request was not sent: ") + dds_strretcode(rc));
  pending_[q.request_id] = {target.sha256, target.revision, false, std::move(done), expire_after_timeout(q.request_id)};
}

dds::EventLoop::TimerId RehearsalRevision::expire_after_timeout(std::uint64_t id) {
  return loop_.after(timeout_, [this, id] {
    auto it = pending_.find(id);
    if (it == pending_.end()) return;
    const Done late = std::move(it->second.done);
    const bool reported = runs(it->second);
    const std::string what = reported ? "the rehearsal cell's simulator did not take the revision (it says: " +
                                            simulator_detail_ + ")"
                             : it->second.applied ? "the rehearsal world model did not report the revision it accepted"
                                                  : "the rehearsal world model did not answer";
    pending_.erase(it);
    late(what + " within " + seconds_text(timeout_));
  });
}

void RehearsalRevision::take() {
  revisions_.take([this](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
    const world_protocol::CellRevision r = world_protocol::from_wire(w);
    running_sha256_ = r.sha256;
    running_revision_ = r.cell_revision;
  });
  states_.take([this](const rigger_system_ServiceState& w, const dds_sample_info_t&) {
    if (dds::to_string(w.kind) != "cell_sim") return;
    simulator_seen_ = true;
    simulator_detail_ = dds::to_string(w.detail);
  });
  replies_.take([this](const rigger_world_CellReply& w, const dds_sample_info_t&) {
    const world_protocol::CellReply rep = world_protocol::from_wire(w);
    if (rep.client_id != client_id_) return;
    auto it = pending_.find(rep.request_id);
    if (it == pending_.end() || it->second.applied) return;
    // The same document under another text (whitespace, key order) runs already: nothing to wait for.
    // Its report may not have reached us yet: then the revision it reports next is that document.
    if (rep.ok || rep.code == world_protocol::cell_code::kUnchanged) {
      it->second.applied = true;
      if (!rep.ok) it->second.sha256 = running_sha256_;
      return;
    }
    loop_.cancel(it->second.timer);
    const Done refused = std::move(it->second.done);
    const std::uint64_t revision = it->second.revision;
    pending_.erase(it);
    refused("the rehearsal world model refused the cell's revision " + std::to_string(revision) + ": " + rep.code +
            ": " + rep.message);
  });
  settle();
}

bool RehearsalRevision::runs(const Pending& p) const {
  if (!p.applied || running_sha256_.empty()) return false;
  return p.sha256.empty() || p.sha256 == running_sha256_;
}

bool RehearsalRevision::simulator_refused() const {
  return simulator_seen_ && simulator_detail_.rfind("refused cell revision " + std::to_string(running_revision_) + ":", 0) == 0;
}

void RehearsalRevision::forget() {
  running_sha256_.clear();
  running_revision_ = 0;
  simulator_detail_.clear();
  simulator_seen_ = false;
}

void RehearsalRevision::settle() {
  const std::string on = "cell revision " + std::to_string(running_revision_);
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (!runs(it->second)) {
      ++it;
      continue;
    }
    // The simulator follows the world model: wait for its word on the same revision, when it has one.
    std::string error;
    if (simulator_refused()) {
      error = "the rehearsal cell's simulator " + simulator_detail_ + " (nothing was rehearsed)";
    } else if (simulator_seen_ && simulator_detail_ != on) {
      ++it;
      continue;
    }
    loop_.cancel(it->second.timer);
    const Done done = std::move(it->second.done);
    it = pending_.erase(it);
    done(error);
  }
}

}  // namespace rigger::console
