#include "echo_node.hpp"

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::echo {

dds::Qos echo_qos() {
  dds::Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}

EchoNode::EchoNode(dds::ServiceContext& ctx)
    : ctx_(ctx),
      max_payload_bytes_(ctx.config.get_in_range<unsigned>("max_payload_bytes", 1u << 20, 0u, 1u << 24)),
      publish_peer_view_(ctx.config.get<bool>("publish_peer_view", true)),
      requests_(ctx.participant, protocol::system::kEchoRequest, echo_qos()),
      replies_(ctx.participant, protocol::system::kEchoReply, echo_qos()),
      directory_(ctx.participant),
      peer_view_(ctx.participant, protocol::system::kPeerView) {
  ctx.config.finish();
  ctx.loop.on_data(requests_, [this] { on_request(); });
  if (publish_peer_view_) {
    ctx.loop.on_data(directory_.reader(), [this] { on_directory(); });
    on_directory();
  }
}

void EchoNode::on_request() {
  requests_.take([this](const rigger_system_EchoSample& req, const dds_sample_info_t&) {
    if (req.payload._length > max_payload_bytes_) {
      ctx_.log->warn("request dropped client={} seq={} payload_bytes={} max={}", dds::to_string(req.client_id),
                     req.seq, req.payload._length, max_payload_bytes_);
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
