#include "rigger/dds/event_loop.hpp"

#include <algorithm>

namespace rigger::dds {

EventLoop::EventLoop(const Participant& participant)
    : waitset_(dds_create_waitset(participant.handle()), "create waitset"),
      guard_(dds_create_guardcondition(participant.handle()), "create guard condition") {
  check(dds_waitset_attach(waitset_.handle(), guard_.handle(), 0), "attach guard condition");
}

EventLoop::~EventLoop() {
  // Detach before the entities die so the waitset never holds a stale handle.
  for (const auto& a : attachments_) dds_waitset_detach(waitset_.handle(), a.entity);
  dds_waitset_detach(waitset_.handle(), guard_.handle());
}

void EventLoop::attach(dds_entity_t entity, uint32_t status_mask, Handler handler) {
  attachments_.push_back({entity, status_mask, std::move(handler)});
  check(dds_waitset_attach(waitset_.handle(), entity, static_cast<dds_attach_t>(attachments_.size())),
        "attach to waitset");
}

void EventLoop::on_data(dds_entity_t reader, Handler handler) {
  // A read condition on any sample state: it stays triggered while the reader holds samples, so a
  // handler that takes them all is called exactly when there is something to do.
  Entity cond(dds_create_readcondition(reader, DDS_ANY_STATE), "create read condition");
  const auto handle = cond.handle();
  read_conditions_.push_back(std::move(cond));
  attach(handle, 0, std::move(handler));
}

void EventLoop::on_status(dds_entity_t entity, uint32_t mask, Handler handler) {
  check(dds_set_status_mask(entity, mask), "set status mask");
  attach(entity, mask, std::move(handler));
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
    handler();
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
    h();
  }
}

bool EventLoop::run_once(std::chrono::nanoseconds timeout) {
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
  const auto n = dds_waitset_wait(waitset_.handle(), triggered, kMaxTriggered, wait);
  if (n < 0) return !stop_;
  for (dds_return_t i = 0; i < n && !stop_; ++i) {
    const auto index = static_cast<size_t>(triggered[i]);
    if (index == 0) {
      bool ignored;
      dds_take_guardcondition(guard_.handle(), &ignored);
      run_posted();
      continue;
    }
    if (index > attachments_.size()) continue;
    // Copy: the handler may attach more entities, reallocating the vector.
    const Attachment a = attachments_[index - 1];
    a.handler();
    if (a.status_mask != 0) {
      uint32_t ignored;
      dds_take_status(a.entity, &ignored, a.status_mask);
    }
  }
  run_due_timers();
  return !stop_;
}

void EventLoop::run() {
  while (run_once(std::chrono::nanoseconds(DDS_INFINITY))) {
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
