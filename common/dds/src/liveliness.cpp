#include "rigger/dds/liveliness.hpp"

namespace rigger::dds {

LivelinessAsserter::LivelinessAsserter(const Participant& participant, std::chrono::milliseconds period,
                                       std::chrono::milliseconds stall_limit)
    : participant_(participant), period_(period.count()), stall_limit_(stall_limit) {
  participant_.assert_liveliness();
  thread_ = std::thread([this] { run(); });
}

LivelinessAsserter::~LivelinessAsserter() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void LivelinessAsserter::loop_alive() noexcept {
  last_alive_.store(std::chrono::steady_clock::now().time_since_epoch().count());
}

void LivelinessAsserter::run() {
  using Clock = std::chrono::steady_clock;
  const auto period = [this] { return std::chrono::milliseconds(period_.load()); };
  auto next = Clock::now() + period();
  std::unique_lock lock(mutex_);
  while (!wake_.wait_until(lock, next, [this] { return stop_; })) {
    const auto now = Clock::now();
    // Deadlines on a fixed grid, so that a late wake-up does not push every later assertion back; after
    // a wake-up later than a whole period (a starved machine), the grid restarts from now.
    next += period();
    if (next <= now) next = now + period();
    const auto alive = last_alive_.load();
    if (stall_limit_.count() == 0 || alive == 0 || now - Clock::time_point(Clock::duration(alive)) <= stall_limit_) {
      participant_.assert_liveliness();
    } else {
      withheld_.fetch_add(1);
    }
  }
}

}  // namespace rigger::dds
