#pragma once
/// @file
/// Follows the cell's revisions for a reader of the cell file (cell_sim, vision_tracker,
/// admittance_control, cad, console): subscribes rigger/world/cell (state QoS: the running revision
/// arrives at once, also to a reader that starts late), reads each new revision with read_revision()
/// against the reader's configured cell file, and hands it to the reader's callback, which takes it or
/// refuses it with a reason.
///
/// A revision whose document is byte for byte the configured cell file's (the world model's first
/// revision is the file as it reads it) is taken without calling back: the reader already runs on it.
/// A revision already taken or refused (same number and sha256, e.g. re-delivered after a world model
/// restart) is ignored.
///
/// Models: a revision that pins a STEP model (model.sha256) this reader's cell folder lacks takes it from
/// rigger/world/cell_model, where the world model publishes the running revision's pinned models. Received
/// models are checked against their sha256 and kept in a folder of this follower's own (removed with
/// it); a revision waits for its models up to `model_wait` (30 s), then is refused naming the model.
///
/// Reporting: every outcome is logged (taken at info, refused at error, with the reason), and, when the
/// follower is given the service's announcer, put in the service state's detail with the current status
/// unchanged ("cell revision 4" or "refused cell revision 5: ..."), so `rigger-compose ps` and the
/// console show it.
///
/// Thread safety: none. Construct, use and destroy on the owner's EventLoop thread; the callback runs on
/// it, never inside a DDS callback. Destroy before the loop.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "rigger/base/logging.hpp"
#include "rigger/cell_follower/cell_revision.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::cell_follower {

/// What a reader did with a revision.
struct Outcome {
  bool taken = true;
  std::string reason;  ///< why it was refused

  static Outcome take() { return {}; }
  static Outcome refuse(std::string why) { return {false, std::move(why)}; }
};

class CellFollower {
 public:
  /// Called with each new revision the follower could read; returns whether the reader took it.
  using OnRevision = std::function<Outcome(const FollowedRevision&)>;

  /// `cell_file`: the reader's configured cell file (errors name it; models resolve against its folder).
  /// `announcer`: optional; gets the outcome in its detail. @throws DdsError.
  CellFollower(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::filesystem::path cell_file,
               OnRevision on_revision, service::ServiceAnnouncer* announcer = nullptr);
  CellFollower(const CellFollower&) = delete;
  CellFollower& operator=(const CellFollower&) = delete;

  /// The revision the reader runs on: the last one taken; 0 before any.
  std::uint64_t revision() const { return revision_; }
  /// Why the last refused revision was refused; empty when none was, or a later one was taken.
  const std::string& last_refusal() const { return last_refusal_; }

  ~CellFollower();

  /// Reads one revision as if it had arrived (the DDS path calls this; tests may too).
  void offer(const world_protocol::CellRevision& sent);

  /// How long a revision waits for a pinned model on rigger/world/cell_model before it is refused.
  static constexpr std::chrono::seconds kModelWait{30};

 private:
  void on_data();
  void on_models();
  void decide(const world_protocol::CellRevision& sent, RevisionReading reading);
  void report(const std::string& detail);

  Logger log_;
  std::filesystem::path cell_file_;
  std::string file_text_;  ///< the configured file's bytes, empty when unreadable
  OnRevision on_revision_;
  service::ServiceAnnouncer* announcer_;
  dds::EventLoop& loop_;
  dds::Reader<rigger_world_CellRevision> reader_;
  dds::Reader<rigger_world_CellModel> models_reader_;
  std::filesystem::path models_root_;  ///< this follower's own: store/ and folders/
  cell::ModelStore models_;
  std::optional<world_protocol::CellRevision> waiting_;  ///< a revision whose pinned models have not come yet
  dds::EventLoop::TimerId wait_timer_ = 0;
  std::uint64_t revision_ = 0;
  std::uint64_t seen_revision_ = 0;
  std::string seen_sha256_;
  std::string last_refusal_;
};

}  // namespace rigger::cell_follower
