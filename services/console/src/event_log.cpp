#include "event_log.hpp"

#include <cstdlib>

namespace rigger::console {

EventLog::EventLog(std::size_t capacity, std::string epoch) : capacity_(capacity), epoch_(std::move(epoch)) {}

std::uint64_t EventLog::append(std::string type, std::string data) {
  std::uint64_t seq = 0;
  {
    std::lock_guard lock(mutex_);
    seq = ++last_seq_;
    events_.push_back({seq, std::move(type), std::move(data)});
    while (events_.size() > capacity_) events_.pop_front();
  }
  changed_.notify_all();
  return seq;
}

std::uint64_t EventLog::last_seq() const {
  std::lock_guard lock(mutex_);
  return last_seq_;
}

std::string EventLog::id_of(std::uint64_t seq) const { return epoch_ + ":" + std::to_string(seq); }

std::optional<std::uint64_t> EventLog::parse_id(const std::string& id) const {
  const auto colon = id.find(':');
  if (colon == std::string::npos || id.compare(0, colon, epoch_) != 0) return std::nullopt;
  const std::string digits = id.substr(colon + 1);
  if (digits.empty() || digits.size() > 19 || digits.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  const std::uint64_t seq = std::strtoull(digits.c_str(), nullptr, 10);
  std::lock_guard lock(mutex_);
  if (seq > last_seq_) return std::nullopt;  // from the future: not ours
  return seq;
}

EventBatch EventLog::wait_after(std::uint64_t after, std::size_t max, std::chrono::milliseconds timeout) {
  EventBatch batch;
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || last_seq_ > after; });
  batch.last_seq = after;
  if (last_seq_ <= after) return batch;
  const std::uint64_t oldest = events_.empty() ? last_seq_ + 1 : events_.front().seq;
  if (after + 1 < oldest) {
    batch.reset = true;
    batch.last_seq = last_seq_;
    return batch;
  }
  for (auto i = static_cast<std::size_t>(after + 1 - oldest); i < events_.size() && batch.events.size() < max; ++i)
    batch.events.push_back(events_[i]);
  batch.last_seq = batch.events.back().seq;
  return batch;
}

std::vector<Event> EventLog::retained() const {
  std::lock_guard lock(mutex_);
  return {events_.begin(), events_.end()};
}

void EventLog::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool EventLog::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

}  // namespace rigger::console
