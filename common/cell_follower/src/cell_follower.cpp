#include "rigger/cell_follower/cell_follower.hpp"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <utility>

#include "rigger/base/sha256.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::cell_follower {
namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.size() > cell::kMaxCellFileBytes ? std::string() : text;
}

// A folder of this follower's own for the models it receives.
std::filesystem::path own_models_root() {
  static unsigned counter = 0;
  return std::filesystem::temp_directory_path() /
         ("rigger-cell-models-" + std::to_string(::getpid()) + "-" + std::to_string(++counter));
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
      loop_(loop),
      reader_(participant, protocol::world::kCell),
      models_reader_(participant, protocol::world::kCellModel),
      models_root_(own_models_root()),
      models_(models_root_ / "store") {
  loop.on_data(models_reader_, [this] { on_models(); });
  loop.on_data(reader_, [this] { on_data(); });
}

CellFollower::~CellFollower() {
  if (wait_timer_ != 0) loop_.cancel(wait_timer_);
  std::error_code error;
  std::filesystem::remove_all(models_root_, error);
}

void CellFollower::on_models() {
  bool stored = false;
  models_reader_.take([&](const rigger_world_CellModel& wire, const dds_sample_info_t&) {
    const world_protocol::CellModel m = world_protocol::from_wire(wire);
    if (!models_.find(m.sha256).empty()) return;
    const std::string problem = cell::model_name_problem(m.name);
    if (!problem.empty() || m.step.size() > cell::kMaxModelBytes || sha256_hex(m.step) != m.sha256) {
      log_->error("cell model refused model=\"{}\" sha256={} bytes={}: {}", m.name.substr(0, 255), m.sha256,
                  m.step.size(), problem.empty() ? "its bytes do not have its sha256 or are too many" : problem);
      return;
    }
    try {
      models_.put(m.step);
      stored = true;
      log_->info("cell model received model={} sha256={} bytes={}", m.name, m.sha256, m.step.size());
    } catch (const std::exception& e) {
      log_->error("cell model not kept model={} sha256={}: {}", m.name, m.sha256, e.what());
    }
  });
  if (stored && waiting_) {
    const world_protocol::CellRevision sent = *waiting_;
    decide(sent, read_revision(sent, cell_file_, {&models_, models_root_ / "folders"}));
  }
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
  decide(sent, read_revision(sent, cell_file_, {&models_, models_root_ / "folders"}));
}

void CellFollower::decide(const world_protocol::CellRevision& sent, RevisionReading reading) {
  if (wait_timer_ != 0) loop_.cancel(wait_timer_);
  wait_timer_ = 0;
  waiting_.reset();
  if (!reading.revision && !reading.missing.empty()) {
    // Its models may still be on their way: wait for them, bounded.
    waiting_ = sent;
    log_->info("cell revision waits for {} model(s) revision={} first={} sha256={}", reading.missing.size(),
               sent.cell_revision, reading.missing.front().name, reading.missing.front().sha256);
    wait_timer_ = loop_.after(kModelWait, [this, refusal = reading.refusal] {
      wait_timer_ = 0;
      if (!waiting_) return;
      const world_protocol::CellRevision late = *waiting_;
      RevisionReading gave_up;
      gave_up.refusal = refusal + " within " + std::to_string(kModelWait.count()) + " s";
      decide(late, std::move(gave_up));
    });
    return;
  }
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
