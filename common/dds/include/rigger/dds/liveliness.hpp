#pragma once
/// @file
/// Asserting a participant's MANUAL_BY_PARTICIPANT liveliness from a thread of its own.
///
/// Peers act on a lost lease: an executor shuts down the skills a lost controller started, admittance
/// control stops when its commander is lost. The lease therefore bounds how long motion can outlive a
/// dead process, and it is short (kDefaultLease, 150 ms). Asserted from the work loop, any stall of the loop
/// longer than the lease (a slow database write, a CPU-starved machine) would be taken for a dead
/// process and fail the task. This thread asserts every `period` instead, independent of what the loop
/// is doing, as long as the loop showed progress (loop_alive()) within `stall_limit`: a killed process
/// is seen within the lease, a hung loop within stall_limit plus the lease.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "rigger/dds/participant.hpp"

namespace rigger::dds {

/// How long a work loop may show no progress before its process stops asserting its liveliness.
inline constexpr std::chrono::milliseconds kLoopStallLimit{1000};

class LivelinessAsserter {
 public:
  /// Starts asserting `participant`'s liveliness every `period`. `stall_limit` zero: always, without
  /// watching a loop (test participants); else, from the first loop_alive() on (a node being built
  /// before its loop runs is alive), only while loop_alive() was called within it.
  LivelinessAsserter(const Participant& participant, std::chrono::milliseconds period,
                     std::chrono::milliseconds stall_limit = kLoopStallLimit);
  ~LivelinessAsserter();
  LivelinessAsserter(const LivelinessAsserter&) = delete;
  LivelinessAsserter& operator=(const LivelinessAsserter&) = delete;

  /// Asserts every `period` from the next assertion on (a node offered a shorter lease). Thread-safe.
  void set_period(std::chrono::milliseconds period) noexcept { period_.store(period.count()); }
  /// The work loop is making progress. Call from the loop at least once per stall_limit. Thread-safe.
  void loop_alive() noexcept;
  /// Assertions skipped because the loop showed no progress within stall_limit (for logs and tests).
  std::uint64_t withheld() const noexcept { return withheld_.load(); }

 private:
  void run();

  const Participant& participant_;
  std::atomic<std::chrono::milliseconds::rep> period_;
  const std::chrono::milliseconds stall_limit_;
  std::atomic<std::chrono::steady_clock::rep> last_alive_{0};  ///< 0: no loop_alive() yet
  std::atomic<std::uint64_t> withheld_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace rigger::dds
