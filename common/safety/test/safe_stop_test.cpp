// The safe stop's listener and writer over DDS in one process: what a device obeying it sees.
#include "rigger/safety/safe_stop.hpp"

#include <gtest/gtest.h>

#include "rigger/testing/domain.hpp"

namespace rigger::safety {
namespace {

using namespace std::chrono_literals;

struct Change {
  std::string resource;
  StopState state;
};

class SafeStopTest : public ::testing::Test {
 protected:
  testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
  SafeStopWriter writer_{participant_};
  std::vector<Change> changes_;
  SafeStopListener::Handler record() {
    return [this](const std::string& r, const StopState& s) { changes_.push_back({r, s}); };
  }
};

TEST_F(SafeStopTest, AStopOfOurResourceIsLatchedUntilItsReset) {
  SafeStopListener crane(participant_, loop_, {"crane", "admittance"}, record());
  ASSERT_TRUE(writer_.writer().wait_for_readers(1, 5s));
  ASSERT_EQ(writer_.command("robot", true, "test", "not ours"), DDS_RETCODE_OK);
  ASSERT_EQ(writer_.command("crane", true, "task_controller", "stop timeout of root/2 passed"), DDS_RETCODE_OK);
  ASSERT_TRUE(loop_.run_until([&] { return !changes_.empty(); }, 5s));
  loop_.run_until([] { return false; }, 50ms);
  ASSERT_EQ(changes_.size(), 1u) << "a stop of another resource reached the crane";
  EXPECT_EQ(changes_[0].resource, "crane");
  EXPECT_TRUE(changes_[0].state.active);
  EXPECT_TRUE(crane.active());
  EXPECT_EQ(crane.describe(), "crane (by task_controller: stop timeout of root/2 passed)");

  ASSERT_EQ(writer_.command("crane", false, "riggerctl", "reset"), DDS_RETCODE_OK);
  ASSERT_TRUE(loop_.run_until([&] { return changes_.size() == 2; }, 5s));
  EXPECT_FALSE(changes_[1].state.active);
  EXPECT_FALSE(crane.active());
  EXPECT_EQ(crane.describe(), "");
}

TEST_F(SafeStopTest, ADeviceThatStartsLateSeesTheStopInForce) {
  ASSERT_EQ(writer_.command("robot", true, "riggerctl", "estop"), DDS_RETCODE_OK);
  SafeStopListener robot(participant_, loop_, {"robot"}, record());
  ASSERT_TRUE(loop_.run_until([&] { return robot.active(); }, 5s));
  EXPECT_EQ(changes_.at(0).state.reason, "estop");
}

TEST_F(SafeStopTest, AResetOfAResourceThatWasNotStoppedChangesNothing) {
  SafeStopListener robot(participant_, loop_, {"robot"}, record());
  ASSERT_TRUE(writer_.writer().wait_for_readers(1, 5s));
  ASSERT_EQ(writer_.command("robot", false, "riggerctl", "reset"), DDS_RETCODE_OK);
  ASSERT_EQ(writer_.command("robot", true, "riggerctl", "estop"), DDS_RETCODE_OK);
  ASSERT_TRUE(loop_.run_until([&] { return !changes_.empty(); }, 5s));
  EXPECT_TRUE(changes_[0].state.active) << "the reset of a running robot was reported as a change";
}

}  // namespace
}  // namespace rigger::safety
