#pragma once
/// @file
/// The controller's side effects off its reaction path: the journal rows and node statuses a handler
/// queued are written by a thread of their own, in the order they were handed over, while the loop
/// goes on serving skill events. A journal commit (a WAL checkpoint now and then takes milliseconds)
/// or a burst of status writes then no longer holds back the event that arrives during it.
///
/// Order is kept: batches are written one after the other, each journal first, then its node
/// statuses (a status a watcher sees is already journaled). drain() waits until everything handed over
/// is written: the node calls it where the journal must be complete (a query, a task's end, a resume).
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include "journal.hpp"
#include "rigger/base/logging.hpp"
#include "status_publisher.hpp"

namespace rigger::task_controller {

class SideEffectWriter {
 public:
  /// When a batch was written (steady clock, ns), kept for the stage trace.
  struct Times {
    std::int64_t began_ns = 0, ended_ns = 0;
  };

  /// `journal` and `status` must outlive the writer; `journal` is shared with the loop thread (it locks).
  /// `keep_times`: remember each batch's Times (times()); for the stage trace only.
  SideEffectWriter(Journal& journal, StatusPublisher& status, Logger log, bool keep_times = false);
  /// Writes what is still queued, then ends its thread.
  ~SideEffectWriter();
  SideEffectWriter(const SideEffectWriter&) = delete;
  SideEffectWriter& operator=(const SideEffectWriter&) = delete;

  /// Queues one batch (either may be empty) and returns its id (1, 2, ...). Never blocks on I/O.
  std::uint64_t hand_over(std::vector<JournalRecord> rows, std::vector<NodeStatusRow> statuses);
  /// Returns once every batch handed over so far is written.
  void drain();
  /// The Times of the batches written so far, by id - 1 (empty unless keep_times).
  std::vector<Times> times() const;

 private:
  struct Batch {
    std::uint64_t id;
    std::vector<JournalRecord> rows;
    std::vector<NodeStatusRow> statuses;
  };
  void run();
  void write(const Batch& batch);

  Journal& journal_;
  StatusPublisher& status_;
  Logger log_;
  const bool keep_times_;
  mutable std::mutex mutex_;
  std::condition_variable queued_, done_;
  std::deque<Batch> queue_;
  std::uint64_t handed_ = 0, written_id_ = 0;
  std::vector<Times> times_;
  bool stopping_ = false;
  std::thread thread_;  ///< last: started once everything it uses is
};

}  // namespace rigger::task_controller
