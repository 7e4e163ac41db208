#pragma once
/// @file
/// The cad process's DDS node: answers rigger/cad/request (commands QoS) on rigger/cad/reply (events
/// QoS) with the request's client_id and request_id. The work (CadService) runs on the loop thread; STEP
/// files are read in a child process, so a hostile file never ends this process.

#include "cad_service.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/cad/settings.hpp"
#include "rigger/cell_follower/cell_follower.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/service/service.hpp"

namespace rigger::cad_service {

/// Settings from the --config file, then config.finish(). @throws ConfigError.
CadServiceSettings read_settings(const Config& config);

/// The node follows the cell's revisions (rigger/world/cell): the objects' models become the revision's.
class CadNode : public service::Node {
 public:
  CadNode(service::ServiceContext& ctx, CadServiceSettings settings);

 private:
  void on_requests();
  cell_follower::Outcome on_revision(const cell_follower::FollowedRevision& revision);
  void log_objects() const;

  service::ServiceContext& ctx_;
  CadService service_;
  dds::Writer<rigger_cad_CadReply> replies_;
  dds::Reader<rigger_cad_CadRequest> requests_;
  cell_follower::CellFollower follower_;  // last: its callback uses the members above
};

}  // namespace rigger::cad_service
