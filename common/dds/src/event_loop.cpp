#include "rigger/dds/event_loop.hpp"

#include <algorithm>

namespace rigger::dds {

namespace {
// The loop whose dispatch lock this thread holds. A handler's own write can be delivered on its
// thread to a reader of the same loop; that listener must queue, not lock again.
thread_local const EventLoop* t_dispatching = nullptr;

class Dispatching {
 public:
  explicit Dispatching(const EventLoop* loop) : previous_(t_dispatching) { t_dispatching = loop; }
  ~Dispatching() { t_dispatching = previous_; }
  Dispatching(const Dispatching&) = delete;
  Dispatching& operator=(const Dispatching&) = delete;

 private:
  const EventLoop* previous_;
};
}  // namespace

EventLoop::EventLoop(const Participant& participant)
    : waitset_(dds_create_waitset(participant.handle()), "create waitset"),
      guard_(dds_create_guardcondition(participant.handle()), "create guard condition") {
  check(dds_waitset_attach(waitset_.handle(), guard_.handle(), 0), "attach guard condition");
}

EventLoop::~EventLoop() {
  // No listener may reach a loop that is gone: dds_set_listener waits for one in progress. A reader
  // already deleted took its listener with it (the call then fails, harmlessly).
  for (const auto& im : immediates_) dds_set_listener(im->reader, nullptr);
  // Detach before the entities die so the waitset never holds a stale handle.
  for (const auto& a : attachments_) dds_waitset_detach(waitset_.handle(), a.entity);
  dds_waitset_detach(waitset_.handle(), guard_.handle());
}

void EventLoop::attach(dds_entity_t entity, uint32_t status_mask, Handler handler, dds_entity_t source) {
  attachments_.push_back({entity, status_mask, std::move(handler), source});
  check(dds_waitset_attach(waitset_.handle(), entity, static_cast<dds_attach_t>(attachments_.size())),
        "attach to waitset");
}

void EventLoop::on_data(dds_entity_t reader, Handler handler) {
  // A read condition on any sample state: it stays triggered while the reader holds samples, so a
  // handler that takes them all is called exactly when there is something to do.
  Entity cond(dds_create_readcondition(reader, DDS_ANY_STATE), "create read condition");
  const auto handle = cond.handle();
  read_conditions_.push_back(std::move(cond));
  attach(handle, 0, std::move(handler), reader);
}

void EventLoop::dispatch(Dispatch what, dds_entity_t entity, const Handler& handler) {
  if (!observer_) {
    handler();
    return;
  }
  observer_(what, entity, true);
  handler();
  observer_(what, entity, false);
}

void EventLoop::on_data_now(dds_entity_t reader, Handler handler) {
  on_data(reader, handler);  // the read condition: the waitset's path outside run()
  auto im = std::make_unique<Immediate>();
  im->loop = this;
  im->reader = reader;
  im->condition = attachments_.back().entity;
  im->index = static_cast<dds_attach_t>(attachments_.size());
  im->handler = std::move(handler);
  // Cyclone 0.10 calls a data-available listener for every delivery, whatever the reader's status
  // mask, and resets the status on invoking it, so a waitset attached to the reader for another status
  // is not woken by data.
  dds_listener_t* listener = dds_create_listener(im.get());
  dds_lset_data_available(listener, &EventLoop::on_available);
  const dds_return_t rc = dds_set_listener(reader, listener);
  dds_delete_listener(listener);
  check(rc, "set data-available listener");
  immediates_.push_back(std::move(im));
}

void EventLoop::on_available(dds_entity_t /*reader*/, void* arg) {
  auto* im = static_cast<Immediate*>(arg);
  EventLoop& loop = *im->loop;
  // Only while run() waits, and never on a thread already dispatching for this loop (a handler's own
  // write delivered to a reader of the same loop): then the loop thread runs it next.
  if (loop.immediate_ok_.load() && t_dispatching != &loop && loop.dispatch_.try_lock()) {
    std::lock_guard<std::mutex> held(loop.dispatch_, std::adopt_lock);
    const Dispatching mark(&loop);
    if (loop.stop_) return;
    loop.dispatch(Dispatch::kListener, im->reader, im->handler);
    // A timer the handler set may be due before the loop's wake-up: wake it to wait less.
    if (!loop.deadlines_.empty() && loop.deadlines_.begin()->first < loop.waiting_until_) {
      loop.waiting_until_ = loop.deadlines_.begin()->first;
      dds_set_guardcondition(loop.guard_.handle(), true);
    }
    return;
  }
  im->pending = true;
  dds_set_guardcondition(loop.guard_.handle(), true);
}

void EventLoop::run_immediates(bool sweep) {
  for (const auto& im : immediates_) {
    if (stop_) return;
    // Pending: delivered while the loop was busy. Sweep: whatever a reader still holds, at the end of
    // every pass of the loop (at least every liveliness period in a service), so that no sample waits
    // on a listener call that did not come. Deleted readers (their endpoint gone) are skipped.
    const bool pending = im->pending.exchange(false);
    if ((pending || (sweep && dds_triggered(im->condition) > 0)) && dds_get_parent(im->reader) > 0)
      dispatch(Dispatch::kPending, im->reader, im->handler);
  }
}

void EventLoop::on_status(dds_entity_t entity, uint32_t mask, Handler handler) {
  check(dds_set_status_mask(entity, mask), "set status mask");
  attach(entity, mask, std::move(handler), entity);
}

EventLoop::TimerId EventLoop::add_timer(Clock::time_point deadline, std::chrono::nanoseconds period,
                                        Handler handler) {
  const TimerId id = next_timer_++;
  timers_.emplace(id, Timer{deadline, period, std::move(handler)});
  deadlines_.emplace(deadline, id);
  return id;
}

EventLoop::TimerId EventLoop::after(std::chrono::nanoseconds delay, Handler handler) {
  return add_timer(Clock::now() + delay, std::chrono::nanoseconds::zero(), std::move(handler));
}

EventLoop::TimerId EventLoop::every(std::chrono::nanoseconds period, Handler handler) {
  return add_timer(Clock::now() + period, period, std::move(handler));
}

void EventLoop::cancel(TimerId id) { timers_.erase(id); }  // its deadline entry is skipped when due

void EventLoop::post(Handler handler) {
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    posted_.push_back(std::move(handler));
  }
  dds_set_guardcondition(guard_.handle(), true);
}

void EventLoop::stop() noexcept {
  stop_ = true;
  dds_set_guardcondition(guard_.handle(), true);
}

void EventLoop::run_due_timers() {
  const auto now = Clock::now();
  while (!deadlines_.empty() && deadlines_.begin()->first <= now && !stop_) {
    const TimerId id = deadlines_.begin()->second;
    deadlines_.erase(deadlines_.begin());
    auto it = timers_.find(id);
    if (it == timers_.end()) continue;  // cancelled
    Handler handler = it->second.handler;  // the handler may cancel its own timer
    if (it->second.period.count() > 0) {
      // Next deadline from the previous one (no drift), but never in the past after a stall.
      it->second.deadline = std::max(it->second.deadline + it->second.period, now);
      deadlines_.emplace(it->second.deadline, id);
    } else {
      timers_.erase(it);
    }
    dispatch(Dispatch::kTimer, 0, handler);
  }
}

void EventLoop::run_posted() {
  std::vector<Handler> work;
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    work.swap(posted_);
  }
  for (auto& h : work) {
    if (stop_) return;
    dispatch(Dispatch::kPosted, 0, h);
  }
}

bool EventLoop::run_once(std::chrono::nanoseconds timeout) {
  std::unique_lock<std::mutex> lock(dispatch_);
  return run_once_locked(lock, timeout);
}

bool EventLoop::run_once_locked(std::unique_lock<std::mutex>& lock, std::chrono::nanoseconds timeout) {
  if (stop_) return false;
  dds_duration_t wait = timeout.count();
  // Skip cancelled timers at the front so they do not cause an early wake-up.
  while (!deadlines_.empty() && !timers_.count(deadlines_.begin()->second)) deadlines_.erase(deadlines_.begin());
  if (!deadlines_.empty()) {
    const auto until = std::chrono::duration_cast<std::chrono::nanoseconds>(deadlines_.begin()->first - Clock::now());
    wait = std::max<dds_duration_t>(0, std::min<dds_duration_t>(wait, until.count()));
  }
  constexpr size_t kMaxTriggered = 64;
  dds_attach_t triggered[kMaxTriggered];
  waiting_until_ = wait >= DDS_INFINITY ? Clock::time_point::max() : Clock::now() + std::chrono::nanoseconds(wait);
  lock.unlock();
  const auto n = dds_waitset_wait(waitset_.handle(), triggered, kMaxTriggered, wait);
  lock.lock();
  const Dispatching mark(this);
  waiting_until_ = Clock::time_point::min();  // busy: a listener that gets the lock wakes nobody
  if (observer_) observer_(Dispatch::kWoke, 0, true);
  if (n < 0) return !stop_;
  for (dds_return_t i = 0; i < n && !stop_; ++i) {
    const auto index = static_cast<size_t>(triggered[i]);
    if (index == 0) {
      bool ignored;
      dds_take_guardcondition(guard_.handle(), &ignored);
      run_immediates(false);
      run_posted();
      continue;
    }
    if (index > attachments_.size()) continue;
    // Copy: the handler may attach more entities, reallocating the vector.
    const Attachment a = attachments_[index - 1];
    dispatch(a.status_mask == 0 ? Dispatch::kData : Dispatch::kStatus, a.source, a.handler);
    if (a.status_mask != 0) {
      uint32_t ignored;
      dds_take_status(a.entity, &ignored, a.status_mask);
    }
  }
  run_due_timers();
  if (immediate_ok_) run_immediates(true);
  return !stop_;
}

void EventLoop::run() {
  std::unique_lock<std::mutex> lock(dispatch_);
  // Inside run() an on_data_now reader is served by its listener: its read condition leaves the
  // waitset, so that a delivery does not also wake the loop thread, and the loop thread runs what the
  // listener could not (pending) and sweeps what is left at the end of each pass. Samples that came
  // before are taken on the first pass.
  for (const auto& im : immediates_) {
    dds_waitset_detach(waitset_.handle(), im->condition);
    im->pending = true;
  }
  if (!immediates_.empty()) dds_set_guardcondition(guard_.handle(), true);
  immediate_ok_ = true;
  while (run_once_locked(lock, std::chrono::nanoseconds(DDS_INFINITY))) {
  }
  immediate_ok_ = false;
  for (const auto& im : immediates_) {
    im->pending = false;  // the read condition is back on the waitset and sees what is left
    dds_waitset_attach(waitset_.handle(), im->condition, im->index);
  }
}

bool EventLoop::run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    const auto left = deadline - Clock::now();
    if (left <= std::chrono::nanoseconds::zero()) return false;
    if (!run_once(std::chrono::duration_cast<std::chrono::nanoseconds>(left))) return done();
  }
  return true;
}

}  // namespace rigger::dds
