#pragma once

#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"

namespace rigger::echo {

/// QoS of the echo topics: reliable keep-last 1, as ddsperf's ping/pong, so the two compare fairly.
dds::Qos echo_qos();

/// Configuration keys (all optional):
///   "max_payload_bytes": integer in [0, 16777216], default 1048576 — larger requests are dropped
///   "publish_peer_view": boolean, default true
class EchoNode : public dds::Node {
 public:
  explicit EchoNode(dds::ServiceContext& ctx);

 private:
  void on_request();
  void on_directory();

  dds::ServiceContext& ctx_;
  unsigned max_payload_bytes_;
  bool publish_peer_view_;
  dds::Reader<rigger_system_EchoSample> requests_;
  dds::Writer<rigger_system_EchoSample> replies_;
  dds::ServiceDirectory directory_;
  dds::Writer<rigger_system_PeerView> peer_view_;
  std::vector<std::string> last_peers_;
};

}  // namespace rigger::echo
