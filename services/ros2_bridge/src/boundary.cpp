#include "boundary.hpp"

#include <cmath>

namespace rigger::ros2_bridge {

std::string_view age_verdict_name(AgeVerdict verdict) {
  switch (verdict) {
    case AgeVerdict::kFresh:
      return "fresh";
    case AgeVerdict::kStale:
      return "stale";
    case AgeVerdict::kFromTheFuture:
      return "from_the_future";
    case AgeVerdict::kUnstamped:
      return "unstamped";
  }
  return "unknown";
}

AgeVerdict check_age(WallTime stamp, WallTime now, const AgeLimits& limits) {
  if (stamp.time_since_epoch().count() == 0) return AgeVerdict::kUnstamped;
  if (stamp > now + limits.max_future_skew) return AgeVerdict::kFromTheFuture;
  if (now - stamp > limits.max_age) return AgeVerdict::kStale;
  return AgeVerdict::kFresh;
}

std::string_view twist_verdict_name(TwistVerdict verdict) {
  switch (verdict) {
    case TwistVerdict::kWithin:
      return "within";
    case TwistVerdict::kClamped:
      return "clamped";
    case TwistVerdict::kOverLimit:
      return "over_limit";
    case TwistVerdict::kNotFinite:
      return "not_finite";
  }
  return "unknown";
}

bool all_finite(const Vector6d& v) {
  return v.allFinite();
}

LimitedTwist limit_twist(const Vector6d& twist, const TwistLimits& limits) {
  if (!all_finite(twist)) return {TwistVerdict::kNotFinite, Vector6d::Zero()};
  const double linear = twist.head<3>().norm();
  const double angular = twist.tail<3>().norm();
  if (linear <= limits.max_linear_mps && angular <= limits.max_angular_radps) return {TwistVerdict::kWithin, twist};
  if (limits.over_limit == OverLimit::kRefuse) return {TwistVerdict::kOverLimit, Vector6d::Zero()};
  Vector6d out = twist;
  if (linear > limits.max_linear_mps) out.head<3>() *= limits.max_linear_mps / linear;
  if (angular > limits.max_angular_radps) out.tail<3>() *= limits.max_angular_radps / angular;
  return {TwistVerdict::kClamped, out};
}

bool RefusalCounter::count(SteadyTime now) {
  ++total_;
  ++pending_;
  if (logged_ && now - last_log_ < interval_) return false;
  logged_ = true;
  last_log_ = now;
  batch_ = pending_;
  pending_ = 0;
  return true;
}

}  // namespace rigger::ros2_bridge
