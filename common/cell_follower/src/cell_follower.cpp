#include "rigger/cell_follower/cell_follower.hpp"

#include <fstream>
#include <iterator>
#include <utility>

#include "rigger/protocol/world.hpp"

namespace rigger::cell_follower {
namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.size() > cell::kMaxCellFileBytes ? std::string() : text;
}

}  // namespace

CellFollower::CellFollower(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                           std::filesystem::path cell_file, OnRevision on_revision,
                           service::ServiceAnnouncer* announcer)
    : log_(std::move(log)),
      cell_file_(std::move(cell_file)),
      file_text_(read_text(cell_file_)),
      on_revision_(std::move(on_revision)),
      announcer_(announcer),
      reader_(participant, protocol::world::kCell) {
  loop.on_data(reader_, [this] { on_data(); });
}

void CellFollower::on_data() {
  // Keep-last 1 per writer: only the newest revision matters, older ones are superseded.
  std::optional<world_protocol::CellRevision> newest;
  reader_.take([&](const rigger_world_CellRevision& wire, const dds_sample_info_t&) {
    world_protocol::CellRevision r = world_protocol::from_wire(wire);
    if (!newest || r.cell_revision >= newest->cell_revision) newest = std::move(r);
  });
  if (newest) offer(*newest);
}

void CellFollower::offer(const world_protocol::CellRevision& sent) {
  if (sent.cell_revision == seen_revision_ && sent.sha256 == seen_sha256_) return;
  seen_revision_ = sent.cell_revision;
  seen_sha256_ = sent.sha256;
  if (!file_text_.empty() && sent.cell_json == file_text_ && revision_ == 0) {
    revision_ = sent.cell_revision;
    log_->info("cell revision taken revision={} as=\"the configured cell file\" file={}", revision_,
               cell_file_.string());
    report("cell revision " + std::to_string(revision_));
    return;
  }
  RevisionReading reading = read_revision(sent, cell_file_);
  Outcome outcome = reading.revision ? on_revision_(*reading.revision) : Outcome::refuse(reading.refusal);
  if (!outcome.taken) {
    last_refusal_ = outcome.reason.rfind("cell revision ", 0) == 0
                        ? outcome.reason
                        : "cell revision " + std::to_string(sent.cell_revision) + ": " + outcome.reason;
    log_->error("cell revision refused revision={} running={} reason=\"{}\"", sent.cell_revision, revision_,
                last_refusal_);
    report("refused " + last_refusal_);
    return;
  }
  revision_ = sent.cell_revision;
  last_refusal_.clear();
  log_->info("cell revision taken revision={} previous={} who=\"{}\" comment=\"{}\"", revision_, sent.previous_revision,
             sent.who, sent.comment);
  report("cell revision " + std::to_string(revision_));
}

void CellFollower::report(const std::string& detail) {
  if (announcer_ != nullptr) announcer_->announce(announcer_->status(), detail);
}

}  // namespace rigger::cell_follower
