#pragma once
/// @file
/// Where the controller's time goes, per executor event: the moment its handler woke, the first
/// command it caused was written, the engine returned, and the journal rows and node statuses it
/// caused were flushed. Opt-in (configuration key "stage_trace_path"): off, the node holds no
/// StageTrace and pays one pointer test per event. On, each event costs a few clock reads and one
/// push_back into memory reserved up front; the records go to a text file when the node ends, so the
/// measurement adds no I/O to the path it measures. Pure C++ (no DDS). Not thread-safe: the node's
/// loop thread only.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace rigger::task_controller {

/// One executor event through the controller. Steady-clock instants are nanoseconds since the clock's
/// epoch (CLOCK_MONOTONIC: comparable across the processes of one host); 0 when the stage did not
/// happen (no command caused; not flushed before the node ended).
struct StageRecord {
  std::string executor_id;
  std::string kind;                ///< SUCCESS, FAILURE, STOPPED, PROGRESS
  std::int64_t stamp_wall_ns = 0;  ///< the event's stamp (its writer's wall clock)
  std::int64_t woke_wall_ns = 0;   ///< the handler woke (this process's wall clock)
  std::int64_t woke_ns = 0;        ///< the handler woke: the event was received from DDS
  std::int64_t writing_ns = 0;     ///< the first command it caused was handed to DDS
  std::int64_t command_ns = 0;     ///< that write returned
  std::int64_t engine_ns = 0;      ///< the engine returned
  std::int64_t flushed_ns = 0;     ///< its journal rows and node statuses were written
};

/// Something else the controller's loop did, near the events: its thread woke, a handler (of events,
/// announcements, a timer, posted work) or a flush began or ended. For the tail of the reaction: what
/// lands between an event and the command it causes.
struct LoopMark {
  std::int64_t ns = 0;  ///< steady clock, as StageRecord's
  std::string what;     ///< e.g. "woke", "listener events", "timer", "flush"
  char phase = '.';     ///< 'b' began, 'e' ended, '.' an instant
};

class StageTrace {
 public:
  using Clock = std::chrono::steady_clock;

  /// Keeps at most `capacity` records (later events are not traced), memory reserved now.
  explicit StageTrace(std::size_t capacity = 200000);

  /// The events' handler began (call once per call, before taking them): in the listener when the loop
  /// was idle, else on the loop thread.
  void woke();
  /// An event taken in this wake enters the engine.
  void begin(const std::string& executor_id, const std::string& kind, std::int64_t stamp_wall_ns);
  /// A command is about to be written / was written (only the first after begin() counts).
  void command_writing();
  void command_written();
  /// The engine returned for the event of the last begin().
  void engine_done();
  /// The queued side effects were written: every traced event not yet flushed was.
  void flushed();
  /// The records before index `count` not flushed yet were flushed at `ns` (the side-effect thread's
  /// time, applied afterwards by the loop thread).
  void flushed_upto(std::size_t count, std::int64_t ns);

  /// Notes what the loop does now (LoopMark), up to the same capacity; `what` is short (no allocation).
  void mark(const char* what, char phase);
  /// The same at `ns`, for what another thread did (write() puts the marks in time order).
  void mark_at(std::int64_t ns, const char* what, char phase);

  const std::vector<StageRecord>& records() const { return records_; }
  const std::vector<LoopMark>& marks() const { return marks_; }
  /// Writes one tab-separated line per record (a header line first) to `path`, and the loop marks, if
  /// any, to `path` + ".loop". Returns false on an I/O error.
  bool write(const std::string& path) const;
  /// Reads a file written by write(); empty when it cannot be read.
  static std::vector<StageRecord> read(const std::string& path);
  /// Reads the loop marks write() wrote beside `path`; empty when there are none.
  static std::vector<LoopMark> read_marks(const std::string& path);

 private:
  std::size_t capacity_;
  std::vector<StageRecord> records_;
  std::vector<LoopMark> marks_;
  std::size_t unflushed_ = 0;  ///< index of the first record not flushed yet
  bool open_ = false;          ///< between begin() and engine_done(), within capacity
  std::int64_t woke_ns_ = 0, woke_wall_ns_ = 0;
};

}  // namespace rigger::task_controller
