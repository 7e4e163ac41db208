#pragma once
/// @file
/// The delay before a crashed service is started again: 0.5 s, doubling with every consecutive crash
/// up to 10 s; an instance that stayed up 30 s or more resets it.

#include <chrono>

namespace rigger::compose {

class RestartBackoff {
 public:
  static constexpr std::chrono::milliseconds kFirst{500};
  static constexpr std::chrono::milliseconds kMax{10000};
  static constexpr std::chrono::milliseconds kStableAfter{30000};

  /// The delay before the next start, given how long the instance that just ended ran. Not thread-safe.
  std::chrono::milliseconds next_delay(std::chrono::milliseconds ran_for);
  /// Forgets earlier crashes (e.g. after a restart the operator asked for).
  void reset() { next_ = kFirst; }

 private:
  std::chrono::milliseconds next_ = kFirst;
};

}  // namespace rigger::compose
