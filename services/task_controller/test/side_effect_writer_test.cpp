// The side-effect writer: batches handed over from the loop are written on its own thread, in order,
// each batch's journal rows before its node statuses (what queued while a transaction ran goes into the
// next together); drain() returns once all of them are written, and
// the loop may read the journal meanwhile. Real node statuses on a private domain, read back by a reader.
#include "side_effect_writer.hpp"

#include <gtest/gtest.h>

#include "rigger/base/logging.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::task_controller {
namespace {

using namespace std::chrono_literals;

class SideEffectWriterTest : public ::testing::Test {
 protected:
  NodeStatusRow status(const std::string& node) {
    NodeStatusRow row;
    row.task_id = "t";
    row.node_id = node;
    row.node_type = "Skill";
    row.state = rigger_task_NODE_RUNNING;
    return row;
  }
  JournalRecord row(const std::string& node) { return {1.0, "t", node, "EVENT", "SUCCESS", "ok"}; }

  rigger::testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::Reader<rigger_task_NodeStatus> statuses_{participant_, protocol::task::kNodeStatus};
  Journal journal_{":memory:"};
  StatusPublisher publisher_{participant_};
};

TEST_F(SideEffectWriterTest, BatchesAreWrittenInOrderAndDrainWaitsForAll) {
  SideEffectWriter writer(journal_, publisher_, make_logger("side-effects-test"), true);
  ASSERT_TRUE(statuses_.wait_for_writers(1, 5s));
  ASSERT_TRUE(journal_.add_task("t", "{}", 1.0));
  constexpr int kBatches = 50;
  for (int b = 0; b < kBatches; ++b) {
    const std::string node = "n" + std::to_string(b);
    EXPECT_EQ(writer.hand_over({row(node + "/a"), row(node + "/b")}, {status(node)}), static_cast<std::uint64_t>(b + 1));
    // The loop reads the journal while the writer writes it.
    EXPECT_TRUE(journal_.has_task("t"));
  }
  writer.drain();

  const auto timeline = journal_.timeline("t", 1000);
  ASSERT_EQ(timeline.size(), 1u + 2 * kBatches);  // the recipe's row, then every batch's two
  for (int b = 0; b < kBatches; ++b) {
    EXPECT_EQ(timeline[1 + 2 * b].node_id, "n" + std::to_string(b) + "/a");
    EXPECT_EQ(timeline[2 + 2 * b].node_id, "n" + std::to_string(b) + "/b");
  }
  const auto times = writer.times();
  ASSERT_EQ(times.size(), static_cast<std::size_t>(kBatches));
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_LE(times[i].began_ns, times[i].ended_ns);
    // Batches queued while a transaction ran go into the next one together and share its times.
    const bool together = i > 0 && times[i - 1].began_ns == times[i].began_ns && times[i - 1].ended_ns == times[i].ended_ns;
    if (i > 0 && !together) {
      EXPECT_LE(times[i - 1].ended_ns, times[i].began_ns) << "transactions overlapped";
    }
  }

  std::vector<std::string> seen;
  dds::EventLoop loop(participant_);
  loop.on_data(statuses_, [&] {
    statuses_.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
      seen.push_back(dds::to_string(s.node_id));
    });
  });
  loop.run_until([&] { return seen.size() >= static_cast<std::size_t>(kBatches); }, 5s);
  ASSERT_EQ(seen.size(), static_cast<std::size_t>(kBatches));
  for (int b = 0; b < kBatches; ++b) EXPECT_EQ(seen[b], "n" + std::to_string(b));
}

TEST_F(SideEffectWriterTest, WhatIsQueuedIsWrittenWhenTheWriterEnds) {
  ASSERT_TRUE(journal_.add_task("t", "{}", 1.0));
  {
    SideEffectWriter writer(journal_, publisher_, make_logger("side-effects-test"));
    for (int b = 0; b < 20; ++b) writer.hand_over({row("n" + std::to_string(b))}, {});
  }  // no drain: the destructor writes what is queued
  EXPECT_EQ(journal_.timeline("t", 1000).size(), 21u);
}

}  // namespace
}  // namespace rigger::task_controller
