#pragma once
/// @file
/// The console's numbered event stream: every change the console saw (a node's transition, a task's
/// state, a prompt, an executor) gets the next number of this run. An SSE client gets "<epoch>:<seq>"
/// as each event's id and resumes with Last-Event-ID; the epoch (fixed at start-up) tells a client
/// whose id came from an earlier run of the console that it must reload the state first.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace rigger::console {

struct Event {
  std::uint64_t seq = 0;
  std::string type;  ///< SSE event name: "node", "task", "prompt", "executor", "plot"
  std::string data;  ///< one line of JSON
};

/// What a client gets after a given id.
struct EventBatch {
  bool reset = false;  ///< the id is from another run, or older than the oldest kept: reload the state
  std::vector<Event> events;
  std::uint64_t last_seq = 0;  ///< the id to continue from
};

/// A bounded, thread-safe log of numbered events. Writers append (the DDS loop); every SSE client
/// thread waits for events after its id.
class EventLog {
 public:
  /// Keeps the last `capacity` events. `epoch` distinguishes runs (e.g. the start time in ms).
  EventLog(std::size_t capacity, std::string epoch);

  /// Appends an event and wakes the waiters; returns its number (1, 2, ...).
  std::uint64_t append(std::string type, std::string data);
  /// The number of the last event (0: none yet).
  std::uint64_t last_seq() const;
  const std::string& epoch() const { return epoch_; }
  /// "<epoch>:<seq>".
  std::string id_of(std::uint64_t seq) const;

  /// Parses a Last-Event-ID: the seq when it is of this run, nullopt otherwise (other run, garbage).
  std::optional<std::uint64_t> parse_id(const std::string& id) const;

  /// Events after `after` (at most `max` of them), waiting up to `timeout` for the first one.
  /// `reset` when events after `after` were already dropped; then `events` is empty and last_seq is
  /// the current last number.
  EventBatch wait_after(std::uint64_t after, std::size_t max, std::chrono::milliseconds timeout);

  /// Every event still kept, oldest first.
  std::vector<Event> retained() const;

  /// Wakes every waiter and makes further waits return at once (shutdown).
  void close();
  bool closed() const;

 private:
  const std::size_t capacity_;
  const std::string epoch_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Event> events_;
  std::uint64_t last_seq_ = 0;
  bool closed_ = false;
};

}  // namespace rigger::console
