#pragma once
/// @file
/// The DDS implementations of the cell devices (cell_devices.hpp):
///  - DdsCraneMonitor: rigger/crane/state (state QoS) and rigger/crane/control (commands QoS);
///  - DdsVisionTracker: rigger/tracker/command (commands QoS) and rigger/tracker/pose (sensor stream QoS);
///  - DdsAdmittanceController: rigger/admittance/command (commands QoS, one seq per command) confirmed by
///    rigger/admittance/state (state QoS) through its last_command_seq;
///  - DdsOperatorPanel: rigger/operator/prompt and rigger/operator/response (state QoS), one prompt_id per
///    prompt ("<source>-<seq>");
///  - DdsWorldAccess: the world model's FEATURES query and pose updates through world_client::WorldClient,
///    and its cell revisions through DdsCellRequests (dds_cell_requests.hpp).
/// Commands carry `source` = the executor id. Sequence numbers start at the wall clock in ns, so that a
/// restarted executor's commands are newer than its predecessor's.
/// Thread safety: the event loop thread; destroy before the loop.

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "dds_cell_requests.hpp"
#include "dds_proxy.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/world_client/world_client.hpp"
#include "topic_condition.hpp"

namespace rigger::skill_sdk {

/// Conversions from the wire (exposed for tests).
CraneSnapshot to_snapshot(const rigger_crane_CraneState& s);
TrackedObjectSample to_sample(const rigger_vision_TrackedPose& s);
AdmittanceSnapshot to_snapshot(const rigger_admittance_AdmittanceState& s);

class DdsCraneMonitor final : public CraneMonitor, private DdsProxy {
 public:
  DdsCraneMonitor(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);
  OpId check_health(std::chrono::nanoseconds max_age, std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId watch_health(std::chrono::nanoseconds max_silence, OpCallback on_problem) override;
  OpId request_external(std::chrono::nanoseconds timeout, OpCallback done) override;
  void cancel(OpId id) override;

 private:
  struct Pending {
    bool external = false;  // request_external (else check_health)
    WallTime since;         // check_health: the oldest acceptable stamp
    std::string link_down;  // check_health: the link-down problem seen while waiting, if any
  };
  void on_state(const CraneSnapshot& s);
  void evaluate(OpId id, const CraneSnapshot& s);
  /// The deadline of a watch: no state for `max_silence` is a problem.
  PendingOps<std::chrono::nanoseconds>::OnDeadline silence(std::chrono::nanoseconds max_silence);

  dds::Writer<rigger_crane_CraneControl> control_;
  TopicCondition<rigger_crane_CraneState, CraneSnapshot> state_;
  PendingOps<Pending> pending_;
  PendingOps<std::chrono::nanoseconds> watches_;  // each with its max_silence; ends at the first problem
};

class DdsVisionTracker final : public VisionTracker, private DdsProxy {
 public:
  DdsVisionTracker(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);
  WallTime command(TrackerRequest request, const std::string& object_id) override;
  OpId watch(const std::string& object_id, std::function<void(const TrackedObjectSample&)> on_sample) override;
  void cancel(OpId id) override { poses_.unsubscribe(id); }

 private:
  dds::Writer<rigger_vision_TrackerCommand> commands_;
  TopicCondition<rigger_vision_TrackedPose, TrackedObjectSample> poses_;
};

class DdsAdmittanceController final : public AdmittanceController, private DdsProxy {
 public:
  DdsAdmittanceController(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);
  OpId command(const AdmittanceRequest& request, std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId watch(std::function<void(const AdmittanceSnapshot&)> on_state) override;
  void cancel(OpId id) override;

 private:
  struct Pending {
    std::uint64_t seq = 0;
    AdmittanceRequest request;
  };
  void on_state(const AdmittanceSnapshot& s);

  dds::Writer<rigger_admittance_AdmittanceCommand> commands_;
  TopicCondition<rigger_admittance_AdmittanceState, AdmittanceSnapshot> state_;
  PendingOps<Pending> pending_;
  std::map<OpId, OpId> watches_;  // our id -> state_ subscription
};

class DdsOperatorPanel final : public OperatorPanel, private DdsProxy {
 public:
  DdsOperatorPanel(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);
  /// Withdraws every prompt still published.
  ~DdsOperatorPanel() override;
  OpId ask(const OperatorPromptSpec& spec, std::chrono::nanoseconds timeout,
           std::function<void(std::optional<std::string>)> done) override;
  void withdraw(OpId id) override;

  /// The prompt_id of `id` ("" when unknown); for tests and logs.
  std::string prompt_id(OpId id) const;

 private:
  struct Prompt {
    std::string prompt_id;
    OperatorPromptSpec spec;
    std::function<void(std::optional<std::string>)> done;  // empty once answered or timed out
    dds::EventLoop::TimerId timer = 0;
  };
  void write(const Prompt& prompt, bool active);
  void on_responses();

  dds::Writer<rigger_operator_ui_OperatorPrompt> prompts_;
  dds::Reader<rigger_operator_ui_OperatorResponse> responses_;
  std::map<OpId, Prompt> open_;
};

class DdsWorldAccess final : public WorldAccess {
 public:
  DdsWorldAccess(world_client::WorldClient& client, const dds::Participant& participant, dds::EventLoop& loop,
                 Logger log, std::string client_id)
      : client_(client), cells_(participant, loop, std::move(log), std::move(client_id)) {}
  OpId features(const std::string& entity, std::chrono::nanoseconds timeout,
                std::function<void(const OpResult&, const nlohmann::json&)> done) override;
  OpId update_pose(const std::string& entity, const std::string& parent_frame, const Eigen::Isometry3d& pose,
                   WallTime stamp, double quality, std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId mark_unlocalized(const std::string& entity, WallTime stamp, std::chrono::nanoseconds timeout,
                        OpCallback done) override;
  OpId running_cell(std::chrono::nanoseconds timeout,
                    std::function<void(const OpResult&, const CellDocument&)> done) override {
    return cells_.running_cell(timeout, std::move(done));
  }
  OpId propose_cell(const CellProposal& proposal, std::chrono::nanoseconds timeout,
                    std::function<void(const OpResult&, const CellProposalAnswer&)> done) override {
    return cells_.propose_cell(proposal, timeout, std::move(done));
  }
  void cancel(OpId id) override {
    if ((id & DdsCellRequests::kIdBit) != 0)
      cells_.cancel(id);
    else
      client_.cancel(id);
  }

 private:
  world_client::WorldClient& client_;
  DdsCellRequests cells_;
};

}  // namespace rigger::skill_sdk
