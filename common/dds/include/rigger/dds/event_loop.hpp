#pragma once
/// @file
/// A service's single work loop: a Cyclone waitset that wakes only on data, on a status change, on a
/// guard condition (stop, posted work) or at the next timer deadline. Nothing polls. Handlers never
/// overlap: they run on the loop's thread, except an on_data_now() handler, which runs on the DDS thread
/// that delivered its sample while run() waits, holding the loop's dispatch lock.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
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
  /// Like on_data, for a reader on a reaction path (the controller's skill events, an executor's
  /// commands). While run() waits, `handler` runs at once in a data-available listener on the DDS thread
  /// that delivered the sample, holding the loop's dispatch lock, so it still never overlaps another
  /// handler or timer. That saves the loop thread's wake-up, one thread hand-off per hop (about 50 us on
  /// the 2-core VM: ddsperf's listener against its waitset triggering). When the loop is busy the
  /// handler runs on the loop thread right after; the loop thread also runs it at the end of any pass
  /// that finds the reader still holding samples. Outside run() (run_once, run_until: tests that look at
  /// state between calls) it runs on the loop thread as on_data's does. The handler must not block on
  /// DDS (a reply it would wait for arrives on the thread it holds); its writes rely on the writer
  /// history watermarks of deploy/cyclonedds.xml (docs/dds.md) never to block.
  void on_data_now(dds_entity_t reader, Handler handler);
  template <typename R>
  void on_data_now(const R& reader, Handler handler) {
    on_data_now(reader.handle(), std::move(handler));
  }
  /// Calls `handler` when a status in `mask` (e.g. DDS_LIVELINESS_CHANGED_STATUS) changes on `entity`.
  /// The loop resets those statuses after the handler; read them inside it with dds_get_*_status.
  void on_status(dds_entity_t entity, uint32_t mask, Handler handler);

  /// Runs `handler` once, `delay` from now. From a handler only (or before run()).
  TimerId after(std::chrono::nanoseconds delay, Handler handler);
  /// Runs `handler` every `period`, first after one period. From a handler only (or before run()).
  TimerId every(std::chrono::nanoseconds period, Handler handler);
  /// Cancels a timer; unknown or fired ids are ignored. From a handler only.
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

  /// What the loop runs, for a trace of its work (observe_dispatch): its thread returned from waiting
  /// (kWoke); an on_data / on_status handler; an on_data_now handler run by its listener (kListener) or,
  /// the loop being busy then, by the loop thread (kPending); a timer; posted work.
  enum class Dispatch { kWoke, kData, kStatus, kListener, kPending, kTimer, kPosted };
  /// `entity`: the reader (kData, kListener, kPending) or the entity whose status changed (kStatus), else 0.
  using DispatchObserver = std::function<void(Dispatch what, dds_entity_t entity, bool begin)>;
  /// Calls `observer` before (begin) and after (!begin) every handler the loop runs, and once (begin) each
  /// time its thread returns from waiting, always holding the dispatch lock, so calls never overlap.
  /// Empty (the default): one test per dispatch. Set it before run(), on the loop's thread.
  void observe_dispatch(DispatchObserver observer) { observer_ = std::move(observer); }

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
    dds_entity_t source;  // the reader of a read condition, else entity
  };
  struct Immediate {  // an on_data_now reader; the listener's argument
    EventLoop* loop = nullptr;
    dds_entity_t reader = 0;
    dds_entity_t condition = 0;  // its read condition: on the waitset outside run(), off it inside
    dds_attach_t index = 0;
    Handler handler;
    std::atomic<bool> pending{false};  // delivered while the loop was busy: the loop runs it next
  };

  static void on_available(dds_entity_t reader, void* arg);
  void run_immediates(bool sweep);
  bool run_once_locked(std::unique_lock<std::mutex>& lock, std::chrono::nanoseconds timeout);

  TimerId add_timer(Clock::time_point deadline, std::chrono::nanoseconds period, Handler handler);
  void attach(dds_entity_t entity, uint32_t status_mask, Handler handler, dds_entity_t source);
  void dispatch(Dispatch what, dds_entity_t entity, const Handler& handler);
  void run_due_timers();
  void run_posted();

  Entity waitset_;
  Entity guard_;
  std::vector<Entity> read_conditions_;
  std::vector<Attachment> attachments_;  // index + 1 is the waitset attach argument (0: guard)
  std::map<TimerId, Timer> timers_;
  std::multimap<Clock::time_point, TimerId> deadlines_;
  TimerId next_timer_ = 1;
  std::vector<std::unique_ptr<Immediate>> immediates_;
  std::atomic<bool> stop_{false};
  // Held by whoever runs handlers: the loop thread except while it waits, or a listener that found it
  // free. Timers and attachments are guarded by it.
  std::mutex dispatch_;
  std::atomic<bool> immediate_ok_{false};     // inside run(): listeners may run handlers
  Clock::time_point waiting_until_ = Clock::time_point::max();  // the loop's next wake-up (dispatch_)
  std::mutex posted_mutex_;
  std::vector<Handler> posted_;
  DispatchObserver observer_;
};

}  // namespace rigger::dds
