#pragma once

#include <string>
#include <vector>

#include "rigger/base/settings.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"
#include "rigger/echo/settings.hpp"

namespace rigger::echo {

/// QoS of the echo topics: reliable keep-last 1, as ddsperf's ping/pong, so the two compare fairly.
dds::Qos echo_qos();

/// The echo service's configuration.
struct EchoSettings {
  unsigned max_payload_bytes{};
  bool publish_peer_view{};
};

class EchoNode : public dds::Node {
 public:
  explicit EchoNode(dds::ServiceContext& ctx) : EchoNode(ctx, read_settings(ctx.config, echo_settings())) {}
  EchoNode(dds::ServiceContext& ctx, const EchoSettings& settings);

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
