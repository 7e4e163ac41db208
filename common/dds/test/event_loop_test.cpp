#include "rigger/dds/event_loop.hpp"

#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
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

// on_data_now: a reader whose handler runs in its data-available listener while run() waits.
class ImmediateReaderTest : public EventLoopTest {
 protected:
  ImmediateReaderTest() { EXPECT_TRUE(writer_.wait_for_readers(1, 5s)); }
  ~ImmediateReaderTest() override {
    loop_.stop();
    if (runner_.joinable()) runner_.join();
  }

  void send(const std::string& id) {
    rigger_task_Recipe r{};
    r.task_id = wire_string(id);
    ASSERT_EQ(writer_.write(r), DDS_RETCODE_OK);
  }
  std::vector<std::string> take_ids() {
    std::vector<std::string> ids;
    reader_.take([&](const rigger_task_Recipe& s, const dds_sample_info_t&) { ids.push_back(to_string(s.task_id)); });
    return ids;
  }
  /// Runs the loop on its own thread; returns that thread's id once run() has served a first post.
  std::thread::id start_running() {
    std::promise<std::thread::id> running;
    loop_.post([&] { running.set_value(std::this_thread::get_id()); });
    runner_ = std::thread([this] { loop_.run(); });
    auto f = running.get_future();
    EXPECT_EQ(f.wait_for(5s), std::future_status::ready);
    return f.get();
  }

  Writer<rigger_task_Recipe> writer_{participant_, "rigger/test/immediate", qos::commands()};
  Reader<rigger_task_Recipe> reader_{participant_, "rigger/test/immediate", qos::commands()};
  std::thread runner_;
};

TEST_F(ImmediateReaderTest, WhileRunWaitsTheHandlerRunsOnTheDeliveringThreadNotTheLoops) {
  std::mutex m;
  std::condition_variable cv;
  std::vector<std::thread::id> handled_on;  // one entry per sample handled
  loop_.on_data_now(reader_, [&] {
    const auto n = take_ids().size();
    std::lock_guard<std::mutex> lock(m);
    handled_on.insert(handled_on.end(), n, std::this_thread::get_id());
    cv.notify_all();
  });
  const auto loop_thread = start_running();
  // A sample that comes while the loop is still busy (its first pass, on a loaded machine) is run by the
  // loop thread, as it should be. So samples go one at a time, each after the last was handled, until one
  // comes while the loop waits; the listener must then have run it.
  bool on_delivering_thread = false;
  for (int i = 0; i < 20 && !on_delivering_thread; ++i) {
    send("a" + std::to_string(i));
    std::unique_lock<std::mutex> lock(m);
    ASSERT_TRUE(cv.wait_for(lock, 5s, [&] { return handled_on.size() > static_cast<std::size_t>(i); }))
        << "sample " << i << " was never handled";
    on_delivering_thread = handled_on.back() != loop_thread;
  }
  EXPECT_TRUE(on_delivering_thread) << "every sample was handled on the loop's thread";
}

TEST_F(ImmediateReaderTest, OutsideRunTheHandlerRunsOnTheLoopThreadLikeOnData) {
  std::vector<std::string> got;
  std::thread::id where;
  loop_.on_data_now(reader_, [&] {
    for (auto& id : take_ids()) got.push_back(id);
    where = std::this_thread::get_id();
  });
  send("b");
  ASSERT_TRUE(loop_.run_until([&] { return !got.empty(); }, 5s));
  EXPECT_EQ(got, std::vector<std::string>{"b"});
  EXPECT_EQ(where, std::this_thread::get_id());
}

TEST_F(ImmediateReaderTest, ADeliveryWhileAHandlerRunsWaitsForItThenRuns) {
  std::vector<std::string> order;  // written by handlers only, which never overlap
  std::promise<void> entered, release, done;
  loop_.on_data_now(reader_, [&] {
    for (auto& id : take_ids()) {
      order.push_back("data " + id);
      done.set_value();
    }
  });
  start_running();
  loop_.post([&] {
    order.push_back("busy begins");
    entered.set_value();
    release.get_future().wait();
    order.push_back("busy ends");
  });
  ASSERT_EQ(entered.get_future().wait_for(5s), std::future_status::ready);
  send("c");  // delivered while the posted handler holds the loop
  release.set_value();
  ASSERT_EQ(done.get_future().wait_for(5s), std::future_status::ready);
  EXPECT_EQ(order, (std::vector<std::string>{"busy begins", "busy ends", "data c"}));
}

TEST_F(ImmediateReaderTest, ATimerThatAnImmediateHandlerSetsWakesTheWaitingLoop) {
  std::promise<void> fired;
  loop_.on_data_now(reader_, [&] {
    if (!take_ids().empty()) loop_.after(20ms, [&] { fired.set_value(); });
  });
  start_running();  // the loop now waits with no deadline at all
  send("d");
  EXPECT_EQ(fired.get_future().wait_for(5s), std::future_status::ready);
}

TEST_F(ImmediateReaderTest, SamplesThatCameBeforeRunAreTakenWhenItStarts) {
  std::promise<std::string> got;
  loop_.on_data_now(reader_, [&] {
    for (auto& id : take_ids()) got.set_value(id);
  });
  send("e");  // outside run(): the listener only marks the reader
  start_running();
  auto f = got.get_future();
  ASSERT_EQ(f.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(f.get(), "e");
}

TEST_F(ImmediateReaderTest, ASampleNoListenerCallBroughtIsTakenAtTheEndOfTheLoopsNextPass) {
  std::promise<std::string> got;
  loop_.on_data_now(reader_, [&] {
    for (auto& id : take_ids()) got.set_value(id);
  });
  loop_.every(20ms, [] {});  // a service's loop passes at least every liveliness period
  start_running();
  // As if Cyclone had not called the listener for this delivery: only the loop's sweep can find it.
  ASSERT_EQ(dds_set_listener(reader_.handle(), nullptr), DDS_RETCODE_OK);
  send("f");
  auto f = got.get_future();
  ASSERT_EQ(f.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(f.get(), "f");
}

}  // namespace
}  // namespace rigger::dds
