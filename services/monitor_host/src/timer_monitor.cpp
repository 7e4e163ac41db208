#include "timer_monitor.hpp"

#include <cstdio>

namespace rigger::monitor {

const MonitorDescription& TimerMonitor::describe() {
  static const MonitorDescription kDescription{
      "TimerMonitor",
      "Fails with TIMEOUT when its duration has elapsed since it was started: a bound on how long the "
      "branch it runs beside may take. Never succeeds.",
      {ParamSpec{"duration_s", ParamType::kNumber, "s", 0.001, 86400.0, std::nullopt, {},
                 "Time after the start at which the monitor fires."}},
      false};
  return kDescription;
}

std::vector<std::string> TimerMonitor::configure(const ParamValues& values) {
  duration_ = from_seconds(values.number("duration_s"));
  return {};
}

void TimerMonitor::start(Stamp start) { start_ = start; }

Verdict TimerMonitor::tick(Stamp now) {
  const auto elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_);
  if (elapsed < duration_) return Verdict::ok();
  char text[96];
  std::snprintf(text, sizeof text, "no result within %.3f s (%.3f s elapsed)", to_seconds(duration_), to_seconds(elapsed));
  return Verdict::fire(kCodeTimeout, text, to_seconds(elapsed));
}

std::optional<Stamp> TimerMonitor::deadline() const {
  return start_ + std::chrono::duration_cast<Stamp::duration>(duration_);
}

}  // namespace rigger::monitor
