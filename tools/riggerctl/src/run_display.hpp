#pragma once
/// @file
/// What `riggerctl run` shows while a task runs and when it ends: the live tree and the time every
/// skill took. Pure formatting (no DDS): node updates in, text out, so it is unit-tested.
///
/// Live view: on a terminal the tree is redrawn in place after every update (one line per node that
/// has started, indented by depth, in tree order); otherwise one line per change is appended, which
/// is what logs and pipes want. Thread safety: none (riggerctl's loop thread).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rigger::ctl {

/// One node as its last NodeStatus described it. Times are wall-clock seconds since the epoch (0: not
/// yet).
struct NodeUpdate {
  std::string id, type, name, state, code, message, executor, progress_text;
  double progress = -1.0;  ///< [0, 1], negative when unknown
  double started_s = 0.0;
  double finished_s = 0.0;
};

/// Orders node ids as the tree does: "root/0/10" after "root/0/9", a parent before its children.
bool tree_order_less(const std::string& a, const std::string& b);

class RunDisplay {
 public:
  /// `redraw`: redraw the tree in place (a terminal); otherwise print one line per change.
  explicit RunDisplay(bool redraw) : redraw_(redraw) {}

  /// Takes an update and returns the text to write to the terminal now (possibly with ANSI cursor
  /// movement when redrawing).
  std::string update(const NodeUpdate& node);

  /// One node's line: indentation, id, type, name, state, progress, executor, code and message.
  static std::string line(const NodeUpdate& node);

  /// The end-of-task report: every skill in the order it first started, with its state, the number of
  /// runs (a Retry runs a skill again), the time of its last run and the total over its runs; then
  /// `wall_s`, the task's wall time.
  std::string durations(double wall_s) const;

  const std::map<std::string, NodeUpdate>& nodes() const { return last_; }
  /// Skill nodes that have started at least once.
  std::size_t skills_run() const;

 private:
  struct Timing {
    double first_started_s = 0.0;
    double last_started_s = 0.0;
    double total_s = 0.0;  ///< over finished runs
    int runs = 0;
  };

  bool redraw_;
  std::map<std::string, NodeUpdate> last_;
  std::map<std::string, Timing> timing_;
  std::size_t drawn_lines_ = 0;
};

}  // namespace rigger::ctl
