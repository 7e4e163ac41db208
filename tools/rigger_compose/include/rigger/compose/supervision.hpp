#pragma once
/// @file
/// The supervisor's decisions, without processes, signals, DDS or clocks of its own: events go in
/// (a process was spawned, announced READY, ended; a deadline passed; stop or restart was asked),
/// commands come out (spawn this service, send this signal to this PID, report this line). The
/// supervisor process (supervisor.hpp) carries the commands out; tests drive it with a fake clock.
///
/// Rules:
/// - Bring-up: a service starts when every service it depends on is READY (a dependency on another
///   host counts when DDS shows it READY). Independent services start together.
/// - Bring-up fails — and everything started is stopped — when a service cannot be spawned, ends
///   before it announced READY, or is not READY within its ready timeout (a remote dependency within
///   its own ready timeout).
/// - After READY, a service that ends on its own is restarted per its policy after the backoff of
///   backoff.hpp; every restart is reported.
/// - Stop: in reverse dependency order (a service gets SIGINT once no running service depends on it),
///   SIGKILL after its stop timeout. Only PIDs this supervision spawned and has not seen end are ever
///   signalled.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "rigger/compose/backoff.hpp"
#include "rigger/compose/compose_file.hpp"

namespace rigger::compose {

using Clock = std::chrono::steady_clock;

/// How a process ended.
struct ExitInfo {
  bool exited = false;  ///< true: exit(code); false: killed by `signal`
  int code = 0;
  int signal = 0;
  bool success() const { return exited && code == 0; }
  /// "exit code 2", "killed by SIGKILL".
  std::string describe() const;
};

enum class ServiceState {
  kWaiting,   ///< not started: waiting for its dependencies
  kStarting,  ///< spawned, waiting for its READY announcement
  kReady,     ///< announced READY
  kBackoff,   ///< ended; starts again when the backoff delay has passed
  kStopping,  ///< SIGINT sent (SIGKILL after the stop timeout)
  kStopped,   ///< ended after a stop, or never started because of one
  kExited,    ///< ended on its own and not restarted (policy)
  kFailed,    ///< could not be started
  kRemote,    ///< runs on another host: only its readiness is watched
};
const char* to_string(ServiceState state);

enum class Phase {
  kStarting,  ///< bringing the services up
  kRunning,   ///< every local service was READY together; restarts per policy
  kStopping,  ///< stopping in reverse dependency order
  kDone,      ///< nothing runs any more
};
const char* to_string(Phase phase);

/// What the supervision knows of one service.
struct ServiceRuntime {
  const ServiceDef* def = nullptr;
  bool local = true;
  ServiceState state = ServiceState::kWaiting;
  int pid = 0;                                ///< the running instance's PID; 0 when none
  int restarts = 0;                           ///< how many times it was started again after its first start
  Clock::time_point started{};                ///< when the current (or last) instance was spawned
  std::optional<Clock::time_point> ready_at;  ///< when the current instance announced READY
  std::optional<Clock::time_point> deadline;  ///< ready timeout, end of backoff, or SIGKILL time
  std::string last_exit;                      ///< how the last instance ended, or why it could not start
  bool remote_ready = false;                  ///< remote services: READY on DDS now

  const std::string& name() const { return def->name; }
};

/// One thing for the supervisor process to do.
struct SupervisionCommand {
  enum class Kind { kSpawn, kSignal, kReport };
  /// kDetail goes to the supervisor's log only; the others also to whoever waits on `up`.
  enum class Level { kDetail, kInfo, kWarn, kError };
  Kind kind = Kind::kReport;
  std::string service;
  int pid = 0;     ///< kSignal
  int signal = 0;  ///< kSignal
  Level level = Level::kInfo;
  std::string text;  ///< kReport
};

class Supervision {
 public:
  /// `plan`: the services to run here and the remote services they depend on, in start order
  /// (start_order.hpp); `local` false marks the remote ones. The definitions must outlive this object.
  struct Entry {
    const ServiceDef* def;
    bool local;
  };
  explicit Supervision(const std::vector<Entry>& plan);

  /// Starts the bring-up at `now`.
  void begin(Clock::time_point now);
  /// The spawn command for `service` succeeded with `pid`.
  void spawned(const std::string& service, int pid, Clock::time_point now);
  /// The spawn command for `service` failed; `error` says why.
  void spawn_failed(const std::string& service, const std::string& error, Clock::time_point now);
  /// The process `pid` ended (already reaped: it is never signalled again). Unknown PIDs are ignored.
  void exited(int pid, const ExitInfo& info, Clock::time_point now);
  /// DDS shows `service` alive and READY, announced by process `pid` (local services: only the
  /// current instance counts).
  void announced_ready(const std::string& service, int pid, Clock::time_point now);
  /// DDS no longer shows `service` READY (only remote services are affected: local ones are watched by PID).
  void announced_lost(const std::string& service, Clock::time_point now);
  /// Stops everything (SIGINT/SIGTERM, `down`). Idempotent.
  void stop(const std::string& reason, Clock::time_point now);
  /// Restarts one local service now (SIGINT, wait, start). Returns an empty string, or why not.
  std::string restart(const std::string& service, Clock::time_point now);
  /// Acts on every deadline at or before `now`.
  void advance(Clock::time_point now);

  /// The commands produced since the last call, in order.
  std::vector<SupervisionCommand> take_commands();
  /// The earliest pending deadline; call advance() then.
  std::optional<Clock::time_point> next_deadline() const;

  Phase phase() const { return phase_; }
  /// True when the bring-up failed; failure() says why.
  bool failed() const { return !failure_.empty(); }
  const std::string& failure() const { return failure_; }
  Clock::time_point began() const { return began_; }
  const std::vector<ServiceRuntime>& services() const { return services_; }
  const ServiceRuntime* find(const std::string& service) const;

 private:
  enum class AfterStop { kNothing, kRestartNow, kRestartPerPolicy };
  struct Extra {
    RestartBackoff backoff;
    AfterStop after_stop = AfterStop::kNothing;
    bool sigkill_sent = false;
  };

  ServiceRuntime* find_mutable(const std::string& service);
  Extra& extra(const ServiceRuntime& s) { return extras_[static_cast<std::size_t>(&s - services_.data())]; }
  void report(SupervisionCommand::Level level, std::string text);
  void spawn(ServiceRuntime& s, Clock::time_point now, bool is_restart);
  void signal_stop(ServiceRuntime& s, AfterStop after, Clock::time_point now);
  void ended_on_its_own(ServiceRuntime& s, bool failed, Clock::time_point now);
  void fail_bring_up(const std::string& reason, Clock::time_point now);
  bool dependencies_ready(const ServiceRuntime& s) const;
  bool has_running_dependant(const ServiceRuntime& s) const;
  void pump(Clock::time_point now);
  std::string elapsed(Clock::time_point now) const;

  std::vector<ServiceRuntime> services_;
  std::vector<Extra> extras_;
  std::vector<SupervisionCommand> commands_;
  Phase phase_ = Phase::kStarting;
  bool begun_ = false;
  Clock::time_point began_{};
  std::string failure_;
};

/// The plan for `up [selected…]` on this host: the selected services and their dependencies (all
/// services when `selected` is empty) that are placed on one of `this_host_names`, plus the services on
/// other hosts that those depend on (waited for, not started), in start order.
/// @throws std::invalid_argument for an unknown name, or a selected service placed on another host.
std::vector<Supervision::Entry> make_plan(const ComposeFile& file, const std::vector<std::string>& selected,
                                          const std::vector<std::string>& this_host_names);

}  // namespace rigger::compose
