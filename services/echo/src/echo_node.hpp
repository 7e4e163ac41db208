#pragma once

#include <string>
#include <vector>

#include "rigger/base/settings.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/echo/settings.hpp"
#include "rigger/service/service.hpp"

namespace rigger::echo {

/// QoS of the echo topics: reliable keep-last 1, as ddsperf's ping/pong, so the two compare fairly.
dds::Qos echo_qos();

/// The echo service's configuration.
struct EchoSettings {
  unsigned max_payload_bytes{};
  bool publish_peer_view{};
};

class EchoNode : public service::Node {
 public:
  explicit EchoNode(service::ServiceContext& ctx) : EchoNode(ctx, read_settings(ctx.config, echo_settings())) {}
  EchoNode(service::ServiceContext& ctx, const EchoSettings& settings);

 private:
  void on_request();
  void on_directory();

  service::ServiceContext& ctx_;
  unsigned max_payload_bytes_;
  bool publish_peer_view_;
  dds::Reader<rigger_system_EchoSample> requests_;
  dds::Writer<rigger_system_EchoSample> replies_;
  service::ServiceDirectory directory_;
  dds::Writer<rigger_system_PeerView> peer_view_;
  std::vector<std::string> last_peers_;
};

}  // namespace rigger::echo
