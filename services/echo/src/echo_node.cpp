#include "echo_node.hpp"

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::echo {

dds::Qos echo_qos() {
  dds::Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}

const SettingsTable<EchoSettings>& echo_settings() {
  using S = EchoSettings;
  static const SettingsTable<S> table{
      setting<S>("max_payload_bytes", 1u << 20, {0u, 1u << 24}, &S::max_payload_bytes,
                 "larger requests are dropped (and logged)"),
      setting<S>("publish_peer_view", true, &S::publish_peer_view,
                 "publish the ready services this process sees on `rigger/system/peer_view`"),
  };
  return table;
}

EchoNode::EchoNode(service::ServiceContext& ctx, const EchoSettings& settings)
    : ctx_(ctx),
      max_payload_bytes_(settings.max_payload_bytes),
      publish_peer_view_(settings.publish_peer_view),
      requests_(ctx.participant, protocol::system::kEchoRequest, echo_qos()),
      replies_(ctx.participant, protocol::system::kEchoReply, echo_qos()),
      directory_(ctx.participant),
      peer_view_(ctx.participant, protocol::system::kPeerView) {
  ctx.loop.on_data(requests_, [this] { on_request(); });
  if (publish_peer_view_) {
    ctx.loop.on_data(directory_.reader(), [this] { on_directory(); });
    on_directory();
  }
}

void EchoNode::on_request() {
  requests_.take([this](const rigger_system_EchoSample& req, const dds_sample_info_t&) {
    const std::size_t payload_bytes = dds::elements(req.payload).size();
    if (payload_bytes > max_payload_bytes_) {
      ctx_.log->warn("request dropped client={} seq={} payload_bytes={} max={}", dds::to_string(req.client_id), req.seq,
                     payload_bytes, max_payload_bytes_);
      return;
    }
    replies_.write(req);  // same key, seq, timestamp and payload: the client measures the round trip
  });
}

void EchoNode::on_directory() {
  directory_.update();
  auto peers = directory_.ready_ids();
  if (peers == last_peers_) return;
  last_peers_ = peers;
  rigger_system_PeerView view{};
  view.observer_id = dds::wire_string(ctx_.options.id);
  std::vector<char*> storage;
  dds::wire_string_sequence(view.alive_peers, peers, storage);
  view.stamp = dds::wire_now();
  peer_view_.write(view);
  ctx_.log->debug("peers changed count={}", peers.size());
}

}  // namespace rigger::echo
