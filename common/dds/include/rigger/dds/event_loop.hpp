#pragma once
/// @file
/// A service's single work loop: a Cyclone waitset that wakes only on data, on a status change, on a
/// guard condition (stop, posted work) or at the next timer deadline. Nothing polls. Handlers run on
/// the loop's thread, never inside a DDS callback.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "rigger/dds/entity.hpp"
#include "rigger/dds/participant.hpp"

namespace rigger::dds {

class EventLoop {
 public:
  using Handler = std::function<void()>;
  using TimerId = std::uint64_t;
  using Clock = std::chrono::steady_clock;

  /// @throws DdsError.
  explicit EventLoop(const Participant& participant);
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;
  ~EventLoop();

  /// Calls `handler` whenever `reader` holds samples. The handler must take them (or it is called again).
  void on_data(dds_entity_t reader, Handler handler);
  template <typename R>
  void on_data(const R& reader, Handler handler) {
    on_data(reader.handle(), std::move(handler));
  }
  /// Calls `handler` when a status in `mask` (e.g. DDS_LIVELINESS_CHANGED_STATUS) changes on `entity`.
  /// The loop resets those statuses after the handler; read them inside it with dds_get_*_status.
  void on_status(dds_entity_t entity, uint32_t mask, Handler handler);

  /// Runs `handler` once, `delay` from now. Loop thread only (or before run()).
  TimerId after(std::chrono::nanoseconds delay, Handler handler);
  /// Runs `handler` every `period`, first after one period. Loop thread only (or before run()).
  TimerId every(std::chrono::nanoseconds period, Handler handler);
  /// Cancels a timer; unknown or fired ids are ignored. Loop thread only.
  void cancel(TimerId id);

  /// Queues `handler` to run on the loop thread and wakes the loop. Thread-safe.
  void post(Handler handler);
  /// Ends run() after the current handler. Thread-safe, async-signal-unsafe (use from a thread).
  void stop() noexcept;
  bool stop_requested() const { return stop_.load(); }

  /// Runs until stop().
  void run();
  /// Runs until `done()` holds (checked after every wake-up) or `timeout` passes; returns done().
  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout);
  /// Waits once for an event (at most `timeout`) and dispatches it. Returns false when stop() was called.
  bool run_once(std::chrono::nanoseconds timeout);

 private:
  struct Timer {
    Clock::time_point deadline;
    std::chrono::nanoseconds period;  // zero: one-shot
    Handler handler;
  };
  struct Attachment {
    dds_entity_t entity;
    uint32_t status_mask;  // 0 for read conditions
    Handler handler;
  };

  TimerId add_timer(Clock::time_point deadline, std::chrono::nanoseconds period, Handler handler);
  void attach(dds_entity_t entity, uint32_t status_mask, Handler handler);
  void run_due_timers();
  void run_posted();

  Entity waitset_;
  Entity guard_;
  std::vector<Entity> read_conditions_;
  std::vector<Attachment> attachments_;  // index + 1 is the waitset attach argument (0: guard)
  std::map<TimerId, Timer> timers_;
  std::multimap<Clock::time_point, TimerId> deadlines_;
  TimerId next_timer_ = 1;
  std::atomic<bool> stop_{false};
  std::mutex posted_mutex_;
  std::vector<Handler> posted_;
};

}  // namespace rigger::dds
