#pragma once
/// @file
/// The controller's half of the skill protocol, the mirror of ExecutorEndpoint (executor_endpoint.hpp):
/// START/SHUTDOWN/PAUSE/RESUME go out on rigger/skill/command with an increasing seq, under a liveliness
/// lease the executors watch (a controller that dies or hangs has its running skills shut down); events
/// come in on rigger/skill/event and must be newer than the last one from the same executor writer
/// (EventOrder); their outcome is read with from_wire (leaf_outcome.hpp), the executor's to_wire read
/// back. Which run an event belongs to, and what the engine makes of it, is the controller's
/// (services/task_controller: match_run, to_leaf_event). EventOrder is pure logic; ControllerEndpoint
/// owns the DDS entities.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/skill_protocol/leaf_outcome.hpp"

namespace rigger::skill_protocol {

/// Where a command goes: the executor of the run, the command's seq (a START's seq is the run's; its
/// events echo it as command_seq), and whether it goes in the executor's partition.
struct CommandRoute {
  std::string executor_id;
  std::uint64_t start_seq = 0;
  /// Its commands go in its executor's partition (ControllerEndpoint::routable, decided at its START and
  /// kept for every later command of the run, so that they stay on one writer, in order).
  bool routed = false;
};

/// Per-writer ordering of events: each executor numbers its events; a seq not above the last one seen
/// from the same writer is a duplicate or out of order.
class EventOrder {
 public:
  /// Whether `seq` is newer than the last accepted from `writer` (then it becomes the last). `last`
  /// receives the last seq before this call.
  bool accept(std::uint64_t writer, std::uint64_t seq, std::uint64_t* last = nullptr);

 private:
  std::map<std::uint64_t, std::uint64_t> last_;
};

/// A SkillEvent that passed the ordering check.
struct ReceivedEvent {
  std::string task_id, node_id, executor_id;
  std::uint64_t seq = 0, command_seq = 0;
  std::int64_t stamp_wall_ns = 0;  ///< the event's stamp (its writer's wall clock)
  /// What the run reports. ACCEPTED (code WAITING or empty) answers the START: for the controller, not
  /// the engine; PAUSED / RESUMED answer a PAUSE / RESUME: for the journal, never the engine.
  LeafOutcome outcome;
};

class ControllerEndpoint {
 public:
  /// `lease`: the liveliness lease offered on the command writer (MANUAL_BY_PARTICIPANT, asserted by
  /// run_service's loop). @throws DdsError.
  ControllerEndpoint(const dds::Participant& participant, std::chrono::milliseconds lease);

  /// An executor announced itself from the participant `participant_key`: makes the writer of its
  /// partition (once) and notes whose reader must match it. `again`: it was lost before (or its
  /// participant changed), so the match is checked afresh.
  void executor_seen(const std::string& executor_id, const dds_guid_t& participant_key, bool again);
  /// Whether a START for `executor_id` can go in its partition now: the executor's own reader has matched
  /// the partition's writer. Until then commands go in the default partition, which it also reads.
  bool routable(const std::string& executor_id);
  /// Whether a START for `executor_id` would reach it now: its reader has matched the writer of its
  /// partition or the default one. A command written before that is lost for good: a volatile reader
  /// never gets what its writer sent before it knew the reader. Announcement and command reader are
  /// discovered separately, so an executor can be seen a moment before it is reachable.
  bool reachable(const std::string& executor_id);
  /// The writer of the default partition: the node watches it for PUBLICATION_MATCHED, which every
  /// executor's reader (it reads the default partition too) raises when it is discovered.
  dds_entity_t default_writer() const { return commands_.handle(); }

  /// The next command seq (every START, SHUTDOWN, PAUSE and RESUME takes one).
  std::uint64_t next_seq() { return ++command_seq_; }
  /// Sends START (params: the leaf's JSON), SHUTDOWN, PAUSE or RESUME of node `node_id` (skill `skill`)
  /// of `task_id` along `route`. Returns false when the write failed.
  bool send(rigger_skill_SkillCommandKind kind, const std::string& task_id, const std::string& node_id,
            const std::string& skill, const CommandRoute& route, const std::string& params, const std::string& reason);

  /// Takes every event: in-order ones to `on_event`, others to `on_out_of_order` (with the last seq).
  void take(const std::function<void(const ReceivedEvent&)>& on_event,
            const std::function<void(const ReceivedEvent&, std::uint64_t last)>& on_out_of_order);

  const dds::Reader<rigger_skill_SkillEvent>& events() const { return events_; }
  /// Calls `before` and `after` around every command write (empty: nothing), for a stage trace.
  void trace_writes(std::function<void()> before, std::function<void()> after) {
    before_write_ = std::move(before);
    after_write_ = std::move(after);
  }

 private:
  /// One executor's partition of the command topic.
  struct Route {
    dds::Writer<rigger_skill_SkillCommand> writer;
    dds_guid_t participant{};  ///< the executor's
    bool matched = false;      ///< the executor's reader has matched `writer`
  };

  const dds::Participant& participant_;
  std::chrono::milliseconds lease_;
  dds::Writer<rigger_skill_SkillCommand> commands_;  ///< the default partition
  std::map<std::string, Route> routes_;              ///< by executor id
  std::map<std::string, dds_guid_t> participants_;   ///< by executor id: the participant it announced from
  dds::Reader<rigger_skill_SkillEvent> events_;
  EventOrder order_;
  std::uint64_t command_seq_ = 0;
  std::function<void()> before_write_, after_write_;
};

}  // namespace rigger::skill_protocol
