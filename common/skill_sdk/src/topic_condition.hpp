#pragma once
/// @file
/// A topic's samples, converted once, for the device proxies: the generic asynchronous primitive "wait
/// for a topic condition, with a timeout" (every sample is offered to the pending waits' predicates; the
/// first sample that satisfies one ends that wait with the sample, and a wait whose timeout passes ends
/// with std::nullopt), subscriptions that see every sample until they end, and the newest sample.
/// Driven by the EventLoop (a read condition and a timer per wait), never polled.
///
/// Thread safety: the event loop thread.

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"

namespace rigger::skill_sdk {

/// `T` is an idlc struct; `Value` the domain value the caller wants (converted from the sample once).
template <typename T, typename Value>
class TopicCondition {
 public:
  using Convert = std::function<Value(const T&)>;
  TopicCondition(const dds::Participant& participant, dds::EventLoop& loop, const protocol::Topic<T>& topic,
                 Convert convert)
      : loop_(loop), reader_(participant, topic), convert_(std::move(convert)) {
    loop_.on_data(reader_, [this] { on_data(); });
  }
  ~TopicCondition() {
    for (auto& [id, wait] : waits_) loop_.cancel(wait.timer);
  }
  TopicCondition(const TopicCondition&) = delete;
  TopicCondition& operator=(const TopicCondition&) = delete;

  /// Waits for a sample whose value satisfies `predicate`; `done(value)` or `done(std::nullopt)` after
  /// `timeout`. Samples already taken do not count (the newest is available as latest()).
  OpId wait(std::function<bool(const Value&)> predicate, std::chrono::nanoseconds timeout,
            std::function<void(std::optional<Value>)> done) {
    const OpId id = ++next_id_;
    const auto timer = loop_.after(timeout, [this, id] {
      auto it = waits_.find(id);
      if (it == waits_.end()) return;
      auto cb = std::move(it->second.done);
      waits_.erase(it);
      cb(std::nullopt);
    });
    waits_.emplace(id, Wait{std::move(predicate), std::move(done), timer});
    return id;
  }
  /// Ends a wait without calling it back.
  void cancel(OpId id) {
    auto it = waits_.find(id);
    if (it == waits_.end()) return;
    loop_.cancel(it->second.timer);
    waits_.erase(it);
  }
  /// Calls `on_sample` with every value from now on, until unsubscribe() with the id returned.
  OpId subscribe(std::function<void(const Value&)> on_sample) {
    const OpId id = ++next_id_;
    subscribers_.emplace(id, std::move(on_sample));
    return id;
  }
  void unsubscribe(OpId id) { subscribers_.erase(id); }
  /// The newest value received, if any.
  const std::optional<Value>& latest() const { return latest_; }
  std::size_t pending() const { return waits_.size(); }

 private:
  struct Wait {
    std::function<bool(const Value&)> predicate;
    std::function<void(std::optional<Value>)> done;
    dds::EventLoop::TimerId timer;
  };

  void on_data() {
    reader_.take([this](const T& sample, const dds_sample_info_t&) {
      latest_ = convert_(sample);
      // Collect first: a callback may start or cancel waits.
      std::vector<std::function<void(std::optional<Value>)>> ready;
      for (auto it = waits_.begin(); it != waits_.end();) {
        if (it->second.predicate(*latest_)) {
          loop_.cancel(it->second.timer);
          ready.push_back(std::move(it->second.done));
          it = waits_.erase(it);
        } else {
          ++it;
        }
      }
      const Value value = *latest_;
      for (auto& cb : ready) cb(value);
      // Callbacks may (un)subscribe: walk a copy of the ids and look each up.
      std::vector<OpId> ids;
      for (const auto& [id, cb] : subscribers_) ids.push_back(id);
      for (OpId id : ids) {
        auto it = subscribers_.find(id);
        if (it == subscribers_.end()) continue;
        auto cb = it->second;  // a copy: the callback may unsubscribe itself
        cb(value);
      }
    });
  }

  dds::EventLoop& loop_;
  dds::Reader<T> reader_;
  Convert convert_;
  std::map<OpId, Wait> waits_;
  std::map<OpId, std::function<void(const Value&)>> subscribers_;
  std::optional<Value> latest_;
  OpId next_id_ = 0;
};

}  // namespace rigger::skill_sdk
