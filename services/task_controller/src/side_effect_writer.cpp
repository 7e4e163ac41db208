#include "side_effect_writer.hpp"

#include <chrono>
#include <iterator>
#include <utility>

namespace rigger::task_controller {
namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

SideEffectWriter::SideEffectWriter(Journal& journal, StatusPublisher& status, Logger log, bool keep_times)
    : journal_(journal), status_(status), log_(std::move(log)), keep_times_(keep_times), thread_([this] { run(); }) {}

SideEffectWriter::~SideEffectWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  queued_.notify_one();
  thread_.join();
}

std::uint64_t SideEffectWriter::hand_over(std::vector<JournalRecord> rows, std::vector<NodeStatusRow> statuses) {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    id = ++handed_;
    queue_.push_back({id, std::move(rows), std::move(statuses)});
  }
  queued_.notify_one();
  return id;
}

void SideEffectWriter::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  const std::uint64_t target = handed_;
  done_.wait(lock, [&] { return written_id_ >= target; });
}

std::vector<SideEffectWriter::Times> SideEffectWriter::times() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return times_;
}

void SideEffectWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    queued_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and everything is written
    // Everything queued goes in one transaction: a writer that fell behind (a slow disk, a loaded
    // machine) catches up at once instead of leaving more batches to a kill.
    std::deque<Batch> taken = std::exchange(queue_, {});
    lock.unlock();
    Batch batch = std::move(taken.front());
    for (std::size_t i = 1; i < taken.size(); ++i) {
      auto& next = taken[i];
      batch.id = next.id;
      batch.rows.insert(batch.rows.end(), std::make_move_iterator(next.rows.begin()),
                        std::make_move_iterator(next.rows.end()));
      batch.statuses.insert(batch.statuses.end(), std::make_move_iterator(next.statuses.begin()),
                            std::make_move_iterator(next.statuses.end()));
    }
    const std::int64_t began = steady_ns();
    write(batch);
    const std::int64_t ended = steady_ns();
    lock.lock();
    if (keep_times_) times_.insert(times_.end(), taken.size(), Times{began, ended});
    written_id_ = batch.id;
    done_.notify_all();
  }
}

void SideEffectWriter::write(const Batch& batch) {
  // The journal first: a node status a watcher sees is already journaled, so a controller killed right
  // after a watcher saw a node start resumes knowing that it started.
  if (!batch.rows.empty()) {
    std::string why;
    if (!journal_.add_records(batch.rows, &why))
      log_->error("journal write failed: {} rows lost, first task={} kind={}: {}", batch.rows.size(),
                  batch.rows.front().task_id, batch.rows.front().kind, why);
  }
  for (const auto& row : batch.statuses)
    if (!status_.node(row)) log_->error("node status write failed task={} node={}", row.task_id, row.node_id);
}

}  // namespace rigger::task_controller
