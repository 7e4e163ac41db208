#pragma once
// Which velocity commands the crane gateway may pass on: fresh ones only.

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rigger::crane_gateway {

/// Wall-clock time: command stamps come from other processes (and hosts), so age is judged on
/// the shared wall clock, not on this process' steady clock.
using WallTime = std::chrono::system_clock::time_point;

/// A crane velocity command as it arrives from the admittance controller or a skill.
struct VelocityCommand {
  Eigen::Vector3d velocity_mps =
      Eigen::Vector3d::Zero();  ///< crane frame: x bridge, y trolley, z up
  WallTime stamp{};             ///< when the sender computed it
  std::uint64_t seq = 0;        ///< increases with every command of a stream
};

/// What the filter made of an offered command.
enum class CommandVerdict {
  kAccepted,
  kStale,            ///< older than the command timeout
  kFromTheFuture,    ///< stamped further ahead of our clock than the allowed skew
  kNotNewer,         ///< sequence number not above the current command's
  kBeforeReconnect,  ///< stamped before the link to the PLC came (back) up
  kNotFinite,        ///< NaN or infinite velocity
  kSafeStop,         ///< a safe stop of the crane is in force (rigger/safety/stop), until its reset
};

/// "accepted", "stale", …
std::string_view verdict_name(CommandVerdict verdict);

/// Keeps the newest fresh velocity command and yields it as the setpoint while it is fresh.
///
/// Rules: a command must be finite, stamped after the last reset() (the reconnect), no older
/// than `timeout` and no further than `max_future_skew` ahead of `now`. While the current
/// command is still fresh, a new one must carry a higher seq (a burst of old samples after a
/// network drop cannot overwrite a newer command); once it has expired, any fresh command
/// starts a new stream (a restarted sender counts from 0 again). setpoint() is zero whenever the
/// current command is older than `timeout`.
/// Pure and not thread-safe; time is passed in.
class VelocityCommandFilter {
 public:
  /// Throws std::invalid_argument for a non-positive timeout or a negative skew.
  explicit VelocityCommandFilter(
      std::chrono::nanoseconds timeout,
      std::chrono::nanoseconds max_future_skew = std::chrono::milliseconds(50));

  CommandVerdict offer(const VelocityCommand& command, WallTime now);
  /// The current command's velocity if fresh at `now`, else zero.
  Eigen::Vector3d setpoint(WallTime now) const;
  /// Whether a fresh command is held at `now`.
  bool fresh(WallTime now) const;
  /// Forgets the current command; from now on only commands stamped after `epoch` count.
  void reset(WallTime epoch);

  std::chrono::nanoseconds timeout() const { return timeout_; }

 private:
  std::chrono::nanoseconds timeout_;
  std::chrono::nanoseconds max_future_skew_;
  std::optional<WallTime> epoch_;
  std::optional<VelocityCommand> current_;
};

}  // namespace rigger::crane_gateway
