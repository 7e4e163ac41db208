#pragma once
/// @file
/// The scaffolding every DDS device proxy (dds_devices.hpp, dds_cell_devices.hpp) shares:
///  - DdsProxy, a base with the event loop, the logger, the `source` its commands carry, the ids of its
///    operations and the sequence numbers of its commands;
///  - PendingOps, the operations in flight, each with its callback and a deadline on the loop, ended
///    exactly once: by finish(), by its deadline's handler, or without a callback by cancel().
/// Thread safety: the event loop thread.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rigger/base/logging.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/skill_sdk/primitives.hpp"

namespace rigger::skill_sdk {

class DdsProxy {
 protected:
  DdsProxy(dds::EventLoop& loop, Logger log, std::string source)
      : loop_(loop),
        log_(std::move(log)),
        source_(std::move(source)),
        // Sequence numbers start at the wall clock so that a restarted executor's commands are newer than
        // its predecessor's for every consumer that compares them.
        seq_(static_cast<std::uint64_t>(to_unix_ns(std::chrono::system_clock::now()))) {}

  /// A new operation id, unique within this proxy.
  OpId next_op() { return ++next_op_; }
  /// The sequence number of the next command.
  std::uint64_t next_seq() { return ++seq_; }
  /// Writes a command; a failed write is logged as "<what> write failed seq=<seq>".
  template <typename T>
  void write_command(const dds::Writer<T>& writer, const T& command, const char* what) {
    if (writer.write(command) != DDS_RETCODE_OK) log_->warn("{} write failed seq={}", what, command.seq);
  }

  dds::EventLoop& loop_;
  Logger log_;
  const std::string source_;

 private:
  OpId next_op_ = 0;
  std::uint64_t seq_;
};

/// Operations in flight; `State` is what a proxy keeps of each (its motion id, its command, ...).
template <typename State>
class PendingOps {
 public:
  using OnDeadline = std::function<void(OpId)>;

  explicit PendingOps(dds::EventLoop& loop) : loop_(loop) {}
  ~PendingOps() {
    for (auto& [id, op] : ops_)
      if (op.timer != 0) loop_.cancel(op.timer);
  }
  PendingOps(const PendingOps&) = delete;
  PendingOps& operator=(const PendingOps&) = delete;

  /// Adds operation `id`; `on_deadline(id)` after `timeout` unless it has ended by then (it usually
  /// finishes the operation with a failure).
  void start(OpId id, State state, OpCallback done, std::chrono::nanoseconds timeout, OnDeadline on_deadline) {
    ops_.emplace(id, Op{std::move(state), std::move(done), 0});
    rearm(id, timeout, std::move(on_deadline));
  }
  /// Replaces the deadline of `id` by a new one `timeout` from now.
  void rearm(OpId id, std::chrono::nanoseconds timeout, OnDeadline on_deadline) {
    auto it = ops_.find(id);
    if (it == ops_.end()) return;
    if (it->second.timer != 0) loop_.cancel(it->second.timer);
    it->second.timer = loop_.after(timeout, [this, id, on_deadline = std::move(on_deadline)] {
      auto op = ops_.find(id);
      if (op == ops_.end()) return;
      op->second.timer = 0;
      on_deadline(id);
    });
  }
  /// The state of `id`, nullptr once it has ended.
  State* find(OpId id) {
    auto it = ops_.find(id);
    return it == ops_.end() ? nullptr : &it->second.state;
  }
  /// The ids in flight, in order (a copy: callbacks may start or end operations).
  std::vector<OpId> ids() const {
    std::vector<OpId> out;
    for (const auto& [id, op] : ops_) out.push_back(id);
    return out;
  }
  /// Ends `id` with `result`: its deadline cancelled, then its callback called. Nothing when it has ended.
  void finish(OpId id, const OpResult& result) {
    auto it = ops_.find(id);
    if (it == ops_.end()) return;
    if (it->second.timer != 0) loop_.cancel(it->second.timer);
    auto done = std::move(it->second.done);
    ops_.erase(it);
    if (done) done(result);
  }
  /// Ends `id` without calling it back; false when it is not in flight.
  bool cancel(OpId id) {
    auto it = ops_.find(id);
    if (it == ops_.end()) return false;
    if (it->second.timer != 0) loop_.cancel(it->second.timer);
    ops_.erase(it);
    return true;
  }

 private:
  struct Op {
    State state;
    OpCallback done;
    dds::EventLoop::TimerId timer = 0;
  };

  dds::EventLoop& loop_;
  std::map<OpId, Op> ops_;
};

}  // namespace rigger::skill_sdk
