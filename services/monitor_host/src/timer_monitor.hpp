#pragma once
/// @file
/// TimerMonitor: fires TIMEOUT once its duration has elapsed since reset (the monitor's START). Put in
/// a Parallel next to a skill, it bounds how long the skill may take.

#include "monitor.hpp"

namespace rigger::monitor {

class TimerMonitor final : public Monitor {
 public:
  /// Name "TimerMonitor"; parameter duration_s (required).
  static const MonitorDescription& describe();
  const MonitorDescription& description() const override { return describe(); }

 protected:
  std::vector<std::string> configure(const ParamValues& values) override;
  void start(Stamp start) override;
  /// Fires TIMEOUT when now − start ≥ duration (value: elapsed s).
  Verdict tick(Stamp now) override;
  std::optional<Stamp> deadline() const override;

 private:
  std::chrono::nanoseconds duration_{0};
  Stamp start_{};
};

}  // namespace rigger::monitor
