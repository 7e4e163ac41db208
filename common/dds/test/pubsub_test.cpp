#include "rigger/dds/pubsub.hpp"

#include <gtest/gtest.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::dds {
namespace {

using namespace std::chrono_literals;

class PubSubTest : public ::testing::Test {
 protected:
  testing::DomainLease domain_;
  Participant participant_{domain_.id()};
  EventLoop loop_{participant_};
};

TEST_F(PubSubTest, WrittenSampleArrivesWithAllFields) {
  Writer<rigger_task_Recipe> writer(participant_, "rigger/test/recipe", qos::commands());
  Reader<rigger_task_Recipe> reader(participant_, "rigger/test/recipe", qos::commands());
  ASSERT_TRUE(writer.wait_for_readers(1, 5s));

  const std::string id = "insert-load", json = R"({"root": {}})", who = "test";
  rigger_task_Recipe r{};
  r.task_id = wire_string(id);
  r.recipe_json = wire_string(json);
  r.submitter = wire_string(who);
  r.stamp = wire_now();
  ASSERT_EQ(writer.write(r), DDS_RETCODE_OK);

  std::vector<std::string> got;
  loop_.on_data(reader, [&] {
    reader.take([&](const rigger_task_Recipe& s, const dds_sample_info_t&) {
      got.push_back(to_string(s.task_id) + "|" + to_string(s.recipe_json) + "|" + to_string(s.submitter));
    });
  });
  ASSERT_TRUE(loop_.run_until([&] { return !got.empty(); }, 5s));
  EXPECT_EQ(got.front(), id + "|" + json + "|" + who);
}

TEST_F(PubSubTest, TransientLocalStateReachesLateJoiner) {
  Writer<rigger_system_PeerView> writer(participant_, "rigger/test/state", qos::state());
  const std::string observer = "early";
  rigger_system_PeerView v{};
  v.observer_id = wire_string(observer);
  ASSERT_EQ(writer.write(v), DDS_RETCODE_OK);

  Reader<rigger_system_PeerView> late(participant_, "rigger/test/state", qos::state());
  std::string seen;
  loop_.on_data(late, [&] {
    late.take([&](const rigger_system_PeerView& s, const dds_sample_info_t&) { seen = to_string(s.observer_id); });
  });
  ASSERT_TRUE(loop_.run_until([&] { return !seen.empty(); }, 5s));
  EXPECT_EQ(seen, "early");
}

TEST_F(PubSubTest, KeepAllCommandsArriveInOrder) {
  Writer<rigger_skill_SkillCommand> writer(participant_, "rigger/test/cmd", qos::commands());
  Reader<rigger_skill_SkillCommand> reader(participant_, "rigger/test/cmd", qos::commands());
  ASSERT_TRUE(writer.wait_for_readers(1, 5s));
  const std::string exec = "x";
  for (uint64_t i = 1; i <= 200; ++i) {
    rigger_skill_SkillCommand c{};
    c.executor_id = wire_string(exec);
    c.seq = i;
    ASSERT_EQ(writer.write(c), DDS_RETCODE_OK);
  }
  std::vector<uint64_t> seqs;
  loop_.on_data(reader, [&] {
    reader.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) { seqs.push_back(c.seq); });
  });
  ASSERT_TRUE(loop_.run_until([&] { return seqs.size() == 200; }, 5s)) << seqs.size();
  for (size_t i = 0; i < seqs.size(); ++i) EXPECT_EQ(seqs[i], i + 1);
}

TEST_F(PubSubTest, BadTopicNameIsATypedError) {
  EXPECT_THROW((Writer<rigger_task_Recipe>(participant_, "bad topic name with spaces?*", qos::commands())), DdsError);
}

}  // namespace
}  // namespace rigger::dds
