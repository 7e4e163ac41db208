#pragma once
/// @file
/// QoS profiles, named after their use. Every topic in docs/topics.md names the profile it uses.

#include <chrono>

#include <dds/dds.h>

#include "rigger/protocol/topic.hpp"

namespace rigger::dds {

/// Move-only owner of a dds_qos_t.
class Qos {
 public:
  Qos();
  Qos(Qos&& other) noexcept;
  Qos& operator=(Qos&& other) noexcept;
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  ~Qos();

  const dds_qos_t* get() const { return qos_; }
  dds_qos_t* get() { return qos_; }

  Qos& reliable(std::chrono::milliseconds max_blocking = std::chrono::milliseconds(100));
  Qos& best_effort();
  Qos& keep_last(int depth);
  Qos& keep_all();
  Qos& volatile_durability();
  Qos& transient_local();
  /// MANUAL_BY_PARTICIPANT liveliness with `lease`: the process asserts it from its work loop, so a hung
  /// thread is noticed, not only a dead process.
  Qos& manual_liveliness(std::chrono::milliseconds lease);

 private:
  dds_qos_t* qos_;
};

/// The default liveliness lease of announcement writers (services, executors): how long a killed
/// commander's motion can go on before its peers stop it. Asserted from a thread of its own
/// (LivelinessAsserter), so that it can be this short without a loop's stall passing for a death.
inline constexpr std::chrono::milliseconds kDefaultLease{150};
/// The liveliness lease of this process's announcement writers: kDefaultLease, or
/// $RIGGER_LIVELINESS_LEASE_MS (an integer in [100, 10000]) where a machine is loaded beyond what the
/// default's 100 ms margin can bear (the test suite, ~2.5 simulated cells per core: docs/testing.md).
/// @throws std::invalid_argument naming the variable when its value is not such an integer.
std::chrono::milliseconds liveliness_lease();
/// The lease of state streams whose every write asserts it (crane and cell state, 50 Hz and faster):
/// readers see a hung writing thread within it. Longer than kDefaultLease: nothing stops on it that a
/// shorter lease would stop sooner (the devices have their own command watchdogs).
inline constexpr std::chrono::milliseconds kStateStreamLease{300};

namespace qos {
/// Commands that must all arrive, in order: reliable, keep-all, volatile (SkillCommand, TaskCommand, Recipe).
Qos commands();
/// Events that must all arrive, in order: reliable, keep-all, volatile (SkillEvent, query replies).
Qos events();
/// Latest state for late joiners: reliable, transient-local, keep-last 1 per instance.
Qos state();
/// The reader side of a state() topic for whoever shows or checks every change, not only the latest
/// (riggerctl run's live tree, tests): keep-last `depth` per instance, so that a burst of changes to
/// one instance (RUNNING, progress, SUCCESS within a millisecond) is not collapsed to its last.
Qos state_changes(int depth = 64);
/// High-rate sensor data where only the newest matters: best effort, keep-last 1, volatile.
Qos sensor_stream();
/// Velocity setpoints: reliable, keep-last 1, volatile (the newest command wins; its age is checked on receipt).
Qos setpoints();
/// Liveliness-monitored announcements: state() plus MANUAL_BY_PARTICIPANT liveliness with `lease`.
Qos announcements(std::chrono::milliseconds lease = liveliness_lease());
/// The profile a topic descriptor names (announcements with the default lease).
Qos of(protocol::QosProfile profile);
}  // namespace qos

}  // namespace rigger::dds
