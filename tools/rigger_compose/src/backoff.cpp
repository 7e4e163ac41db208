#include "rigger/compose/backoff.hpp"

#include <algorithm>

namespace rigger::compose {

std::chrono::milliseconds RestartBackoff::next_delay(std::chrono::milliseconds ran_for) {
  if (ran_for >= kStableAfter) next_ = kFirst;
  const auto delay = next_;
  next_ = std::min(next_ * 2, kMax);
  return delay;
}

}  // namespace rigger::compose
