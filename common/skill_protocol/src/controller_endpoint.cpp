#include "rigger/skill_protocol/controller_endpoint.hpp"

#include <cstring>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/dds/qos.hpp"

namespace rigger::skill_protocol {
namespace {

/// The skill-command writer's QoS: commands() with MANUAL_BY_PARTICIPANT liveliness, asserted by
/// run_service's loop every third of the shortest lease offered (the node offers this one).
dds::Qos supervised_commands(std::chrono::milliseconds lease) {
  dds::Qos q = dds::qos::commands();
  q.manual_liveliness(lease);
  return q;
}

}  // namespace

bool EventOrder::accept(std::uint64_t writer, std::uint64_t seq, std::uint64_t* last) {
  auto& l = last_[writer];
  if (last) *last = l;
  if (seq <= l) return false;
  l = seq;
  return true;
}

ControllerEndpoint::ControllerEndpoint(const dds::Participant& participant, std::chrono::milliseconds lease)
    : participant_(participant),
      lease_(lease),
      commands_(participant, protocol::skill::kCommand, supervised_commands(lease)),
      events_(participant, protocol::skill::kEvent) {}

namespace {

/// Whether a reader of the participant `participant_key` has matched `writer`.
bool has_reader_of(dds_entity_t writer, const dds_guid_t& participant_key) {
  constexpr std::size_t kMax = 64;
  dds_instance_handle_t readers[kMax];
  const dds_return_t n = dds_get_matched_subscriptions(writer, readers, kMax);
  bool found = false;
  for (dds_return_t i = 0; i < n && static_cast<std::size_t>(i) < kMax && !found; ++i) {
    dds_builtintopic_endpoint_t* e = dds_get_matched_subscription_data(writer, readers[i]);
    if (e == nullptr) continue;
    found = std::memcmp(&e->participant_key, &participant_key, sizeof participant_key) == 0;
    dds_builtintopic_free_endpoint(e);
  }
  return found;
}

}  // namespace

void ControllerEndpoint::executor_seen(const std::string& executor_id, const dds_guid_t& participant_key, bool again) {
  participants_[executor_id] = participant_key;
  auto it = routes_.find(executor_id);
  if (it == routes_.end()) {
    const std::string partition = protocol::skill::command_partition(executor_id);
    if (partition.empty()) return;  // an id no partition can name alone: the default partition it is
    dds::Qos qos = supervised_commands(lease_);
    dds::set_partitions(qos, {partition});
    it = routes_
             .emplace(executor_id,
                      Route{dds::Writer<rigger_skill_SkillCommand>(participant_, protocol::skill::kCommand, qos),
                            participant_key, false})
             .first;
    return;
  }
  Route& r = it->second;
  if (again || std::memcmp(&r.participant, &participant_key, sizeof participant_key) != 0) {
    r.participant = participant_key;
    r.matched = false;
  }
}

bool ControllerEndpoint::routable(const std::string& executor_id) {
  const auto it = routes_.find(executor_id);
  if (it == routes_.end()) return false;
  Route& r = it->second;
  if (r.matched) {
    // Cheap check that it still has a reader; a lost and found executor is checked afresh (executor_seen).
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(r.writer.handle(), &st) == DDS_RETCODE_OK && st.current_count > 0)
      return true;
    r.matched = false;
  }
  r.matched = has_reader_of(r.writer.handle(), r.participant);
  return r.matched;
}

bool ControllerEndpoint::reachable(const std::string& executor_id) {
  if (routable(executor_id)) return true;
  const auto it = participants_.find(executor_id);
  // Not seen here (a test's executor that never announced itself): nothing to check it against.
  if (it == participants_.end()) return true;
  return has_reader_of(commands_.handle(), it->second);
}

bool ControllerEndpoint::send(rigger_skill_SkillCommandKind kind, const std::string& task_id,
                              const std::string& node_id, const std::string& skill, const CommandRoute& run,
                              const std::string& params, const std::string& reason) {
  rigger_skill_SkillCommand c{};
  c.executor_id = dds::wire_string(run.executor_id);
  c.task_id = dds::wire_string(task_id);
  c.node_id = dds::wire_string(node_id);
  c.skill = dds::wire_string(skill);
  c.kind = kind;
  c.params_json = dds::wire_string(params);
  c.reason = dds::wire_string(reason);
  c.seq = run.start_seq;
  c.stamp = dds::wire_now();
  auto& writer = run.routed ? routes_.at(run.executor_id).writer : commands_;
  if (before_write_) before_write_();
  const bool written = writer.write(c) == DDS_RETCODE_OK;
  if (after_write_) after_write_();
  return written;
}

void ControllerEndpoint::take(const std::function<void(const ReceivedEvent&)>& on_event,
                              const std::function<void(const ReceivedEvent&, std::uint64_t last)>& on_out_of_order) {
  events_.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t& info) {
    ReceivedEvent r;
    r.task_id = dds::to_string(e.task_id);
    r.node_id = dds::to_string(e.node_id);
    r.executor_id = dds::to_string(e.executor_id);
    r.seq = e.seq;
    r.command_seq = e.command_seq;
    r.stamp_wall_ns = static_cast<std::int64_t>(e.stamp.sec) * 1000000000LL + e.stamp.nanosec;
    std::uint64_t last = 0;
    if (!order_.accept(info.publication_handle, e.seq, &last)) {
      on_out_of_order(r, last);
      return;
    }
    r.outcome = from_wire(e);
    on_event(r);
  });
}

}  // namespace rigger::skill_protocol
