#pragma once
/// @file
/// Which streamed velocity commands the simulated robot driver applies: a command's age
/// is checked on receipt against its own timeout, and a stream's sequence numbers must grow. Pure:
/// time is passed in, no DDS.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string_view>

#include "rigger/base/time.hpp"

namespace rigger::cell_sim {

/// What the gate made of an offered command.
enum class GateVerdict {
  kAccepted,
  kStale,          ///< older than its own timeout on receipt
  kFromTheFuture,  ///< stamped further ahead of our clock than the allowed skew
  kNotNewer,       ///< seq not above the current command's while that one is still in force
  kBadTimeout,     ///< timeout not positive or not finite
};

/// "accepted", "stale", ...
std::string_view verdict_name(GateVerdict verdict);

/// Admits fresh commands of a velocity stream and says until when the current one holds.
///
/// A command is accepted when its timeout is positive, its age (now - stamp) is at most its timeout
/// and at least -max_future, and, while the current command is still in force, its seq is higher
/// (a burst of old samples after a network drop cannot override a newer command). Once the current
/// command has expired, any fresh command starts a new stream (a restarted sender counts from 0
/// again). An accepted command holds until stamp + min(timeout, max_timeout).
/// Not thread-safe.
class CommandGate {
 public:
  /// @throws std::invalid_argument for a negative skew or a non-positive max_timeout.
  CommandGate(std::chrono::nanoseconds max_future, std::chrono::nanoseconds max_timeout);

  GateVerdict offer(WallTime stamp, std::uint64_t seq, double timeout_s, WallTime now);
  /// When the current command stops holding; nullopt before the first accepted command.
  std::optional<WallTime> expiry() const { return expiry_; }
  /// Forgets the current command (e-stop, reset): the next fresh command is accepted whatever its seq.
  void reset();

 private:
  std::chrono::nanoseconds max_future_;
  std::chrono::nanoseconds max_timeout_;
  std::optional<std::uint64_t> seq_;
  std::optional<WallTime> expiry_;
};

}  // namespace rigger::cell_sim
