#include "command_gate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rigger::cell_sim {

std::string_view verdict_name(GateVerdict verdict) {
  switch (verdict) {
    case GateVerdict::kAccepted:
      return "accepted";
    case GateVerdict::kStale:
      return "stale";
    case GateVerdict::kFromTheFuture:
      return "from_the_future";
    case GateVerdict::kNotNewer:
      return "not_newer";
    case GateVerdict::kBadTimeout:
      return "bad_timeout";
  }
  return "unknown";
}

CommandGate::CommandGate(std::chrono::nanoseconds max_future, std::chrono::nanoseconds max_timeout)
    : max_future_(max_future), max_timeout_(max_timeout) {
  if (max_future_.count() < 0) throw std::invalid_argument("command gate: max_future must not be negative");
  if (max_timeout_.count() <= 0) throw std::invalid_argument("command gate: max_timeout must be positive");
}

GateVerdict CommandGate::offer(WallTime stamp, std::uint64_t seq, double timeout_s, WallTime now) {
  if (!std::isfinite(timeout_s) || timeout_s <= 0.0) return GateVerdict::kBadTimeout;
  const auto timeout = std::min(from_seconds(std::min(timeout_s, 1e6)), max_timeout_);
  const auto age = now - stamp;
  if (age > from_seconds(timeout_s)) return GateVerdict::kStale;
  if (-age > max_future_) return GateVerdict::kFromTheFuture;
  const bool in_force = expiry_ && now < *expiry_;
  if (in_force && seq_ && seq <= *seq_) return GateVerdict::kNotNewer;
  seq_ = seq;
  expiry_ = stamp + std::chrono::duration_cast<WallTime::duration>(timeout);
  return GateVerdict::kAccepted;
}

void CommandGate::reset() {
  seq_.reset();
  expiry_.reset();
}

}  // namespace rigger::cell_sim
