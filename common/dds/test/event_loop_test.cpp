#include "rigger/dds/event_loop.hpp"

#include <thread>

#include <gtest/gtest.h>

#include "rigger/testing/domain.hpp"

namespace rigger::dds {
namespace {

using namespace std::chrono_literals;

class EventLoopTest : public ::testing::Test {
 protected:
  testing::DomainLease domain_;
  Participant participant_{domain_.id()};
  EventLoop loop_{participant_};
};

TEST_F(EventLoopTest, TimersFireInDeadlineOrderAndNotEarly) {
  std::vector<int> order;
  const auto start = std::chrono::steady_clock::now();
  std::chrono::steady_clock::duration first_at{};
  loop_.after(30ms, [&] { order.push_back(2); });
  loop_.after(10ms, [&] {
    order.push_back(1);
    first_at = std::chrono::steady_clock::now() - start;
  });
  ASSERT_TRUE(loop_.run_until([&] { return order.size() == 2; }, 2s));
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
  EXPECT_GE(first_at, 10ms);
}

TEST_F(EventLoopTest, PeriodicTimerRepeatsAndCancels) {
  int ticks = 0;
  EventLoop::TimerId id = 0;
  id = loop_.every(5ms, [&] {
    if (++ticks == 3) loop_.cancel(id);
  });
  bool later = false;
  loop_.after(60ms, [&] { later = true; });
  ASSERT_TRUE(loop_.run_until([&] { return later; }, 2s));
  EXPECT_EQ(ticks, 3);
}

TEST_F(EventLoopTest, CancelledTimerNeverRuns) {
  bool ran = false, done = false;
  const auto id = loop_.after(5ms, [&] { ran = true; });
  loop_.cancel(id);
  loop_.after(20ms, [&] { done = true; });
  ASSERT_TRUE(loop_.run_until([&] { return done; }, 2s));
  EXPECT_FALSE(ran);
}

TEST_F(EventLoopTest, StopFromAnotherThreadWakesRun) {
  std::thread stopper([&] {
    // A post from another thread must wake the blocked loop; the posted handler then stops it.
    loop_.post([&] { loop_.stop(); });
  });
  loop_.run();  // returns only because of the post: there are no timers or readers
  stopper.join();
  EXPECT_TRUE(loop_.stop_requested());
}

TEST_F(EventLoopTest, RunUntilTimesOutWhenNothingHappens) {
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(loop_.run_until([] { return false; }, 50ms));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);
}

}  // namespace
}  // namespace rigger::dds
