// The controller's commands go to the leaf's executor alone once that executor's reader has matched the
// writer of its partition (rigger/protocol/skill.hpp: command_partition); before that, and for a run
// whose START went in the default partition, every executor gets them. Real DDS on a private domain:
// one participant for the controller's endpoint and one per executor, each with an executor's reader.
#include <gtest/gtest.h>

#include <functional>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/skill_protocol/controller_endpoint.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::skill_protocol {
namespace {

using namespace std::chrono_literals;

dds_guid_t guid_of(const dds::Participant& p) {
  dds_guid_t g{};
  EXPECT_EQ(dds_get_guid(p.handle(), &g), DDS_RETCODE_OK);
  return g;
}

/// An executor's command reader in its own participant (with its own loop: a waitset holds the entities
/// of one participant), and the nodes of the commands it took.
struct Executor {
  Executor(std::uint32_t domain, const std::string& id)
      : participant(domain),
        loop(participant),
        reader(participant, protocol::skill::kCommand, dds::qos::executor_commands(id)) {
    loop.on_data(reader, [this] {
      reader.take([this](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
        nodes.push_back(dds::to_string(c.node_id));
      });
    });
  }
  dds::Participant participant;
  dds::EventLoop loop;
  dds::Reader<rigger_skill_SkillCommand> reader;
  std::vector<std::string> nodes;
};

/// Turns the loops (a millisecond each at most) until `done` holds or `timeout` passes.
bool spin(const std::vector<dds::EventLoop*>& loops, const std::function<bool()>& done,
          std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    for (auto* l : loops) l->run_once(1ms);
  }
  return true;
}

TEST(CommandRouting, ARoutedCommandReachesItsExecutorAloneAndAnUnroutedOneReachesAll) {
  rigger::testing::DomainLease domain;
  dds::Participant controller(domain.id());
  dds::EventLoop loop(controller);
  ControllerEndpoint endpoint(controller, 300ms);
  Executor a(domain.id(), "a"), b(domain.id(), "b");
  const std::vector<dds::EventLoop*> loops = {&loop, &a.loop, &b.loop};
  EXPECT_FALSE(endpoint.routable("a")) << "no announcement yet: no partition writer";
  endpoint.executor_seen("a", guid_of(a.participant), false);
  endpoint.executor_seen("b", guid_of(b.participant), false);
  // Discovery: the partition writers match the executors' readers.
  ASSERT_TRUE(spin(
      loops, [&] { return endpoint.routable("a") && endpoint.routable("b"); }, 10s));

  const CommandRoute to_a{"a", endpoint.next_seq(), true};
  const CommandRoute to_b{"b", endpoint.next_seq(), true};
  const CommandRoute unrouted{"a", endpoint.next_seq(), false};  // a START before a's reader matched goes here
  ASSERT_TRUE(endpoint.send(rigger_skill_SKILL_START, "t", "root/0", "Localize", to_a, "{}", ""));
  ASSERT_TRUE(endpoint.send(rigger_skill_SKILL_START, "t", "root/1", "Localize", to_b, "{}", ""));
  ASSERT_TRUE(endpoint.send(rigger_skill_SKILL_START, "t", "root/2", "Localize", unrouted, "{}", ""));
  ASSERT_TRUE(spin(
      loops, [&] { return a.nodes.size() >= 2 && b.nodes.size() >= 2; }, 10s))
      << "a took " << a.nodes.size() << ", b took " << b.nodes.size();
  // A command written before would have arrived by now (one host, loopback); let 200 ms more pass.
  spin(
      loops, [] { return false; }, 200ms);
  EXPECT_EQ(a.nodes, (std::vector<std::string>{"root/0", "root/2"}));
  EXPECT_EQ(b.nodes, (std::vector<std::string>{"root/1", "root/2"}));

  // The executor's participant changed (it restarted): the match is checked again, against the new one.
  Executor a2(domain.id(), "a");
  endpoint.executor_seen("a", guid_of(a2.participant), true);
  EXPECT_TRUE(spin(
      {&loop, &a2.loop}, [&] { return endpoint.routable("a"); }, 10s));
}

TEST(CommandRouting, AnIdWithAWildcardHasNoPartitionOfItsOwn) {
  EXPECT_EQ(protocol::skill::command_partition("skills"), "rigger.executor.skills");
  EXPECT_EQ(protocol::skill::command_partition("a*"), "");
  EXPECT_EQ(protocol::skill::command_partition("a?b"), "");
  EXPECT_EQ(protocol::skill::command_partition("[ab]"), "");
  EXPECT_EQ(protocol::skill::command_partition(""), "");
}

// An executor is reachable once its reader has matched a writer of the controller: an announcement
// alone (here: a participant with no command reader) is not enough.
TEST(CommandRouting, AnExecutorIsReachableOnlyOnceItsCommandReaderIsMatched) {
  rigger::testing::DomainLease domain;
  dds::Participant controller(domain.id());
  dds::EventLoop loop(controller);
  ControllerEndpoint endpoint(controller, 300ms);
  dds::Participant bare(domain.id());
  endpoint.executor_seen("a", guid_of(bare), false);
  endpoint.executor_seen("b*", guid_of(bare), false);  // no partition of its own: the default one only
  EXPECT_FALSE(spin(
      {&loop}, [&] { return endpoint.reachable("a") || endpoint.reachable("b*"); }, 300ms))
      << "reachable with no reader at all";
  Executor a(domain.id(), "a"), b(domain.id(), "b*");
  endpoint.executor_seen("a", guid_of(a.participant), false);
  endpoint.executor_seen("b*", guid_of(b.participant), false);
  EXPECT_TRUE(spin(
      {&loop, &a.loop, &b.loop}, [&] { return endpoint.reachable("a") && endpoint.reachable("b*"); }, 10s));
}

}  // namespace
}  // namespace rigger::skill_protocol
