#pragma once
// How a stop went in a scenario test, by the samples' own stamps (the processes share this machine's clock):
// from a mark (the first SKILL_PAUSE, a link cut, a kill) the commands and speeds of the robot and the crane,
// and when each came to rest. ScenarioCell feeds it from its readers.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "rigger/base/time.hpp"

namespace rigger::testing::scenario {

class StopTimeline {
 public:
  using Clock = std::chrono::steady_clock;
  /// What a traced sample measures.
  enum Kind { kTwistCommand, kToolSpeed, kCraneCommand, kPlcSetpoint, kCraneSpeed, kAdmittanceMode, kKinds };
  /// Which plant a rest sample is of.
  enum class Plant { kTool, kCrane };

  /// Whether a stop was marked.
  bool marked() const { return stop_mark_.has_value(); }

  /// Marks the start of a stop at wall-clock time `t` (the first SKILL_PAUSE on rigger/skill/command marks
  /// itself with its stamp; a test marks a link cut or a kill): rest_after_mark_s() and timeline() count
  /// from it. Every sample is timed by its own stamp (the processes share this machine's clock), not by when
  /// this process read it, so that a test process the scheduler holds back does not lengthen the figures.
  void mark(WallTime t) {
    stop_mark_ = t;
    rest_after_mark_s_.reset();
    tool_rest_ = {};
    crane_rest_ = {};
    stop_trace_.clear();
  }
  /// The same at steady-clock time `t`.
  void mark(Clock::time_point t) {
    mark(std::chrono::system_clock::now() -
         std::chrono::duration_cast<std::chrono::system_clock::duration>(Clock::now() - t));
  }

  /// From the stop's mark (the first SKILL_PAUSE, or mark()) to the first moment, by the samples' stamps,
  /// at which the newest robot state (the tool's reported twist) and the newest simulator status (the crane's
  /// true speed) both show less than 1 mm/s. Empty before a mark, or while still moving. (Until 2026-11-26 the
  /// crane's part was the status this process had read when a robot state arrived: a status stream read late
  /// made it up to 200 ms longer than the trace showed.)
  std::optional<double> rest_after_mark_s() const { return rest_after_mark_s_; }
  /// The same for the tool alone and for the crane alone (each first seen below 1 mm/s).
  std::optional<double> tool_rest_after_mark_s() const { return tool_rest_.first_still_s; }
  std::optional<double> crane_rest_after_mark_s() const { return crane_rest_.first_still_s; }

  /// Where the stop's time went, by the samples' stamps (for the first 1.5 s after the mark):
  /// per 20 ms, the largest commanded robot twist (rigger/robot/cmd_twist), the tool's reported speed, the
  /// commanded crane velocity (rigger/crane/cmd_velocity), the PLC's setpoint and the crane's true speed
  /// (rigger/sim/status), all in mm/s, and the admittance mode; then, for each, when it last exceeded 1 mm/s.
  std::string timeline(double until_s) const {
    constexpr double kBinS = 0.02;
    const int bins = static_cast<int>(until_s / kBinS);
    std::vector<std::array<double, kKinds>> table(bins);
    for (auto& row : table) row.fill(-1.0);
    std::array<double, kKinds> last_above{};
    last_above.fill(-1.0);
    for (const Sample& x : stop_trace_) {
      const int bin = static_cast<int>(x.t_s / kBinS);
      if (bin >= 0 && bin < bins) table[bin][x.kind] = std::max(table[bin][x.kind], x.value);
      if (x.kind != kAdmittanceMode && x.value >= 0.001) last_above[x.kind] = x.t_s;
    }
    std::string out = "  ms   twist cmd  tool  crane cmd  plc set  crane  admittance mode\n";
    char line[160];
    for (int b = 0; b < bins; ++b) {
      const auto& r = table[b];
      auto mm = [](double v) { return v < 0.0 ? std::string("    -") : std::to_string(v * 1000.0).substr(0, 5); };
      std::snprintf(line, sizeof line, "  %3d  %9s  %5s  %9s  %7s  %5s  %s\n", static_cast<int>(b * kBinS * 1000),
                    mm(r[kTwistCommand]).c_str(), mm(r[kToolSpeed]).c_str(), mm(r[kCraneCommand]).c_str(),
                    mm(r[kPlcSetpoint]).c_str(), mm(r[kCraneSpeed]).c_str(),
                    r[kAdmittanceMode] < 0.0 ? "-" : std::to_string(static_cast<int>(r[kAdmittanceMode])).c_str());
      out += line;
    }
    std::snprintf(line, sizeof line,
                  "  last above 1 mm/s (ms): twist cmd %.0f, tool %.0f, crane cmd %.0f, plc set %.0f, crane %.0f\n",
                  last_above[kTwistCommand] * 1000, last_above[kToolSpeed] * 1000, last_above[kCraneCommand] * 1000,
                  last_above[kPlcSetpoint] * 1000, last_above[kCraneSpeed] * 1000);
    return out + line;
  }
  /// When the tool and the crane (as timeline() reads them) were last faster than 1 mm/s after the mark,
  /// in s: the time from which both stayed below it. Empty before a mark.
  std::optional<double> settled_after_mark_s() const {
    if (!stop_mark_) return std::nullopt;
    double last = 0.0;
    for (const Sample& x : stop_trace_)
      if ((x.kind == kToolSpeed || x.kind == kCraneSpeed) && x.value >= 0.001) last = std::max(last, x.t_s);
    return last;
  }

  /// Records sample `value` of `kind` (m/s, or the admittance mode) stamped `stamp`: in the first 1.5 s
  /// after the mark, for timeline().
  void trace(int kind, double value, WallTime stamp) {
    if (!stop_mark_) return;
    const double t = std::chrono::duration<double>(stamp - *stop_mark_).count();
    if (t >= 0.0 && t < 1.5) stop_trace_.push_back({t, kind, value});
  }
  /// Records a speed sample of the tool or the crane; once the newest samples of both (by stamp, whichever
  /// stream the test process read first) are below 1 mm/s, the rest is the later of the two runs' starts.
  void note_rest(Plant plant, double speed_mps, WallTime stamp) {
    RestTrack& track = plant == Plant::kTool ? tool_rest_ : crane_rest_;
    if (!stop_mark_ || stamp < *stop_mark_) return;
    const double t = std::chrono::duration<double>(stamp - *stop_mark_).count();
    const bool still = speed_mps < 0.001;
    if (still && !track.first_still_s) track.first_still_s = t;
    if (track.latest_t_s && *track.latest_t_s > t) return;  // an older sample read late
    if (still && !(track.latest_t_s && track.latest_still)) track.still_since_s = t;
    track.latest_t_s = t;
    track.latest_still = still;
    if (!rest_after_mark_s_ && tool_rest_.latest_t_s && crane_rest_.latest_t_s && tool_rest_.latest_still &&
        crane_rest_.latest_still)
      rest_after_mark_s_ = std::max(tool_rest_.still_since_s, crane_rest_.still_since_s);
  }

 private:
  std::optional<WallTime> stop_mark_;
  std::optional<double> rest_after_mark_s_;
  /// One plant's speed after the mark, by its samples' stamps: the newest sample's, and the first below 1 mm/s.
  struct RestTrack {
    std::optional<double> latest_t_s;
    bool latest_still = false;
    double still_since_s = 0.0;  ///< the first sample of the current run below 1 mm/s
    std::optional<double> first_still_s;
  };
  RestTrack tool_rest_, crane_rest_;
  struct Sample {
    double t_s;
    int kind;
    double value;
  };
  std::vector<Sample> stop_trace_;
};

}  // namespace rigger::testing::scenario
