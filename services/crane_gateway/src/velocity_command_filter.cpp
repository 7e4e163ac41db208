#include "velocity_command_filter.hpp"

#include <stdexcept>

namespace rigger::crane_gateway {

std::string_view verdict_name(CommandVerdict verdict) {
  switch (verdict) {
    case CommandVerdict::kAccepted:
      return "accepted";
    case CommandVerdict::kStale:
      return "stale";
    case CommandVerdict::kFromTheFuture:
      return "from_the_future";
    case CommandVerdict::kNotNewer:
      return "not_newer";
    case CommandVerdict::kBeforeReconnect:
      return "before_reconnect";
    case CommandVerdict::kNotFinite:
      return "not_finite";
    case CommandVerdict::kSafeStop:
      return "safe_stop";
  }
  return "unknown";
}

VelocityCommandFilter::VelocityCommandFilter(std::chrono::nanoseconds timeout,
                                             std::chrono::nanoseconds max_future_skew)
    : timeout_(timeout), max_future_skew_(max_future_skew) {
  if (timeout_ <= std::chrono::nanoseconds::zero()) {
    throw std::invalid_argument("command timeout must be positive");
  }
  if (max_future_skew_ < std::chrono::nanoseconds::zero()) {
    throw std::invalid_argument("command max future skew must not be negative");
  }
}

CommandVerdict VelocityCommandFilter::offer(const VelocityCommand& command, WallTime now) {
  if (!command.velocity_mps.allFinite()) {
    return CommandVerdict::kNotFinite;
  }
  if (epoch_ && command.stamp <= *epoch_) {
    return CommandVerdict::kBeforeReconnect;
  }
  if (now - command.stamp > timeout_) {
    return CommandVerdict::kStale;
  }
  if (command.stamp - now > max_future_skew_) {
    return CommandVerdict::kFromTheFuture;
  }
  if (fresh(now) && command.seq <= current_->seq) {
    return CommandVerdict::kNotNewer;
  }
  current_ = command;
  return CommandVerdict::kAccepted;
}

bool VelocityCommandFilter::fresh(WallTime now) const {
  return current_.has_value() && now - current_->stamp <= timeout_;
}

Eigen::Vector3d VelocityCommandFilter::setpoint(WallTime now) const {
  return fresh(now) ? current_->velocity_mps : Eigen::Vector3d::Zero();
}

void VelocityCommandFilter::reset(WallTime epoch) {
  epoch_ = epoch;
  current_.reset();
}

}  // namespace rigger::crane_gateway
