#include "rigger/dds/liveliness.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "rigger/dds/event_loop.hpp"
#include "rigger/service/service_state.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::service {
namespace {

using dds::EventLoop;
using dds::LivelinessAsserter;
using dds::Participant;

using namespace std::chrono_literals;

/// An observer's service directory, and a service "svc" on another participant that announces READY with
/// a 150 ms lease, asserted every 50 ms by the asserter under test.
class LivelinessAsserterTest : public ::testing::Test {
 protected:
  /// Starts the service with `stall_limit` and waits until the observer sees it ready.
  void start(std::chrono::milliseconds stall_limit) {
    liveliness_ = std::make_unique<LivelinessAsserter>(service_, 50ms, stall_limit);
    announcer_.announce(ServiceStatus::kReady);
    ASSERT_TRUE(loop_.run_until([&] { return dir_.is_ready("svc"); }, 5s));
  }
  bool ready() const { return dir_.is_ready("svc"); }
  void SetUp() override {
    loop_.on_data(dir_.reader(), [this] { dir_.update(); });
  }

  testing::DomainLease domain_;
  Participant observer_{domain_.id()};
  EventLoop loop_{observer_};
  ServiceDirectory dir_{observer_};
  Participant service_{domain_.id()};
  ServiceAnnouncer announcer_{service_, "svc", "echo", 150ms};
  std::unique_ptr<LivelinessAsserter> liveliness_;
};

// The asserting thread keeps a service alive while its loop stalls for longer than the lease, as long
// as the stall is shorter than the stall limit: a slow loop is not a dead process.
TEST_F(LivelinessAsserterTest, AStallShorterThanTheLimitCostsNoLease) {
  start(2s);
  liveliness_->loop_alive();
  // No loop_alive() for four leases: the service must stay ready all along.
  EXPECT_FALSE(loop_.run_until([&] { return !ready(); }, 600ms))
      << "the service was lost while its loop stalled for less than the stall limit";
  EXPECT_EQ(liveliness_->withheld(), 0U);
}

// A loop that shows no progress for longer than the stall limit is taken for hung: the thread stops
// asserting, and peers see the service lost within the stall limit plus the lease.
TEST_F(LivelinessAsserterTest, ALoopStalledPastTheLimitLosesItsLease) {
  start(300ms);
  // Until its loop first shows progress the service is being built, and alive: no assertion withheld.
  EXPECT_EQ(liveliness_->withheld(), 0U);
  liveliness_->loop_alive();  // the loop runs once, then hangs
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(loop_.run_until([&] { return !ready(); }, 5s));
  const auto lost_after = std::chrono::steady_clock::now() - t0;
  EXPECT_GT(liveliness_->withheld(), 0U);
  EXPECT_LT(lost_after, 2s) << "loss seen after "
                            << std::chrono::duration_cast<std::chrono::milliseconds>(lost_after).count() << " ms";
}

// While the loop keeps showing progress, the service stays ready however long it runs.
TEST_F(LivelinessAsserterTest, ALiveLoopKeepsItsLease) {
  start(300ms);
  const auto end = std::chrono::steady_clock::now() + 800ms;
  bool lost = false;
  while (!lost && std::chrono::steady_clock::now() < end) {
    liveliness_->loop_alive();
    loop_.run_once(20ms);
    lost = !ready();
  }
  EXPECT_FALSE(lost) << "the service was lost although its loop showed progress";
  EXPECT_EQ(liveliness_->withheld(), 0U);
}

}  // namespace
}  // namespace rigger::service
