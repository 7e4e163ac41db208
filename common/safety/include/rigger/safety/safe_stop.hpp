#pragma once
/// @file
/// The software safe stop on rigger/safety/stop: one latched instance per resource ("robot", "crane",
/// "gripper", "admittance"). A device that obeys it stops at once (zero velocity, hold position; a
/// gripper keeps its state, so a load is never dropped), refuses motion commands while the stop is in
/// force, and moves again only after a reset naming the resource. The topic is state QoS
/// (transient-local), so a device that starts late still sees a stop in force.
///
/// This is not a safety-rated channel (DDS and Linux are not): the e-stop and hard limits of the robot
/// controller and the crane PLC stay the safety functions; the safe stop is the supervisor's way to
/// bring the cell to rest when a skill did not (stop timeout passed, failed safe stop, controller
/// shutdown, `riggerctl estop`).

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/safety.hpp"

namespace rigger::safety {

/// The resources a safe stop can name.
const std::vector<std::string>& stoppable_resources();

/// A stop as last written for one resource.
struct StopState {
  bool active = false;
  std::string source;
  std::string reason;
};

/// Follows rigger/safety/stop for the resources a device obeys. `on_change(resource, state)` runs on the
/// loop's thread for every change of one of them (a stop, or its reset).
class SafeStopListener {
 public:
  using Handler = std::function<void(const std::string& resource, const StopState& state)>;
  /// @throws DdsError.
  SafeStopListener(const dds::Participant& participant, dds::EventLoop& loop, std::vector<std::string> resources,
                   Handler on_change);
  /// Whether a stop of any of our resources is in force.
  bool active() const;
  /// "crane (by task_controller: stop timeout of node root/2 passed)", the stops in force, "; "-joined.
  std::string describe() const;

 private:
  void on_data();

  std::vector<std::string> resources_;
  Handler on_change_;
  dds::Reader<rigger_safety_SafeStop> reader_;
  std::map<std::string, StopState> stops_;
};

/// Commands safe stops and their resets.
class SafeStopWriter {
 public:
  /// @throws DdsError.
  explicit SafeStopWriter(const dds::Participant& participant);
  /// Writes a stop (active) or a reset of `resource`. Returns the DDS return code; never throws.
  dds_return_t command(const std::string& resource, bool active, const std::string& source,
                       const std::string& reason) const;
  /// The underlying writer (to wait for readers).
  const dds::Writer<rigger_safety_SafeStop>& writer() const { return writer_; }

 private:
  dds::Writer<rigger_safety_SafeStop> writer_;
};

}  // namespace rigger::safety
