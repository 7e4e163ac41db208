#pragma once
/// @file
/// The rehearsal cell on the real cell's revision (docs/console.md, "Rehearsal"): before a rehearsal is
/// sent, the console applies the document of the real cell's running revision to the rehearsal domain's
/// world model — the CellRequest APPLY of `riggerctl cell apply` — and waits until that world model
/// reports the revision's sha256 on rigger/world/cell (cell_sim follows it from there). The world models
/// stay apart: only this DDS exchange connects them.
///
/// DDS plumbing on the rehearsal participant; everything runs on the console's loop.
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/types.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::console {

/// The real cell's running revision, as its world model showed it (GET /api/cell).
struct CellTarget {
  std::uint64_t revision = 0;
  std::string sha256;     ///< empty: unknown (no world model answers on the cell's domain)
  std::string cell_json;  ///< the document's text
  /// The STEP models the document pins, as the cell's world model published them (rigger/world/cell_model):
  /// the rehearsal world model's folder may lack them.
  std::vector<world_protocol::CellModel> models;
};

class RehearsalRevision {
 public:
  /// Called once on the loop: "" when the rehearsal world model runs the target (reported its sha256, or
  /// answered that the document equals its running one), else why not.
  using Done = std::function<void(const std::string& error)>;

  /// Joins the cell topics on `participant` (the rehearsal domain's). `timeout`: from the APPLY to the
  /// world model's report of the revision. @throws DdsError.
  RehearsalRevision(const dds::Participant& participant, dds::EventLoop& loop, std::string client_id,
                    std::chrono::milliseconds timeout);
  ~RehearsalRevision();
  RehearsalRevision(const RehearsalRevision&) = delete;
  RehearsalRevision& operator=(const RehearsalRevision&) = delete;

  /// The readers whose data must wake the loop to call take().
  std::array<dds_entity_t, 3> readers() const { return {replies_.handle(), revisions_.handle(), states_.handle()}; }
  void take();

  /// A world model reads cell requests on the rehearsal domain.
  bool world_model() const { return requests_.matched_readers() > 0; }
  /// The rehearsal world model's running revision's sha256 ("" before it said).
  const std::string& running_sha256() const { return running_sha256_; }
  /// What the rehearsal cell's simulator last said of its cell revision ("" before it said).
  const std::string& simulator_detail() const { return simulator_detail_; }

  /// The rehearsal cell's simulator refused the revision its world model runs ("refused cell revision N:").
  bool simulator_refused() const;
  /// Forgets what the rehearsal cell said (its world model's revision, its simulator's word): it is being
  /// started again, and only what the new one says counts.
  void forget();

  /// Brings the rehearsal world model to `target` (journaled there as `who`), then calls `done` once the
  /// rehearsal cell's simulator (a service of kind cell_sim, when there is one) says it runs on that
  /// revision too; when it refused it (a revision that reshapes the crane's load needs its restart),
  /// `done` gets its reason: a rehearsal on other physics than the revision's would prove nothing.
  void bring_to(const CellTarget& target, const std::string& who, Done done);

 private:
  void settle();  // calls `done` for the applied revisions the world model now reports
  dds::EventLoop::TimerId expire_after_timeout(std::uint64_t id);  // fails pending `id` after the timeout

  dds::EventLoop& loop_;
  dds::Writer<rigger_world_CellRequest> requests_;
  dds::Reader<rigger_world_CellReply> replies_;
  dds::Reader<rigger_world_CellRevision> revisions_;
  dds::Reader<rigger_system_ServiceState> states_;
  std::string client_id_;
  std::chrono::milliseconds timeout_;
  std::uint64_t next_request_ = 1;
  std::string running_sha256_;
  std::uint64_t running_revision_ = 0;  ///< the rehearsal world model's number of it
  std::string simulator_detail_;        ///< what the rehearsal cell_sim last said of its cell revision
  bool simulator_seen_ = false;
  struct Pending {
    std::string sha256;  ///< empty: whatever runs (the world model said the document runs already)
    std::uint64_t revision = 0;
    bool applied = false;  ///< the world model accepted it; its report on rigger/world/cell is awaited
    Done done;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::uint64_t, Pending> pending_;  ///< by request id
  /// Whether `p` was accepted and its document is the one the world model reports running.
  bool runs(const Pending& p) const;
};

}  // namespace rigger::console
