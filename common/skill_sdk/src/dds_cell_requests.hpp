#pragma once
/// @file
/// The world model's cell revisions as a skill reaches them (WorldAccess::running_cell, propose_cell):
/// rigger/world/cell_request (commands QoS) answered on rigger/world/cell_reply (events QoS), correlated by
/// this executor's client id and a request id. The pair is opened at the first request, so that an executor
/// whose skills never revise the cell holds no writer of cell requests (under DDS Security only the
/// identities granted cell requests may open it: robot-skills, riggerctl, console).
/// A read (CELL_SHOW) is sent again every 500 ms until answered: the world model's reply writer may not
/// have discovered a pair opened just now. A proposal is sent once, after a read was answered.
/// Thread safety: the event loop thread; destroy before the loop.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::skill_sdk {

class DdsCellRequests {
 public:
  DdsCellRequests(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string client_id);
  ~DdsCellRequests();
  DdsCellRequests(const DdsCellRequests&) = delete;
  DdsCellRequests& operator=(const DdsCellRequests&) = delete;

  /// Ids of these operations have this bit set (apart from the world client's).
  static constexpr OpId kIdBit = OpId{1} << 62;

  OpId running_cell(std::chrono::nanoseconds timeout, std::function<void(const OpResult&, const CellDocument&)> done);
  OpId propose_cell(const CellProposal& proposal, std::chrono::nanoseconds timeout,
                    std::function<void(const OpResult&, const CellProposalAnswer&)> done);
  void cancel(OpId id);

 private:
  using Answer = std::function<void(const std::optional<world_protocol::CellReply>&)>;
  struct Pending {
    world_protocol::CellRequest request;
    bool resend = false;
    Answer done;
    dds::EventLoop::TimerId deadline = 0;
    dds::EventLoop::TimerId again = 0;
  };
  OpId ask(world_protocol::CellRequest request, bool resend, std::chrono::nanoseconds timeout, Answer done);
  void send(OpId id);
  void finish(OpId id, const std::optional<world_protocol::CellReply>& reply);
  void open();

  const dds::Participant& participant_;
  dds::EventLoop& loop_;
  Logger log_;
  std::string client_id_;
  std::optional<dds::Writer<rigger_world_CellRequest>> requests_;
  std::optional<dds::Reader<rigger_world_CellReply>> replies_;
  std::map<OpId, Pending> pending_;
  std::uint64_t next_ = 0;
};

}  // namespace rigger::skill_sdk
