#pragma once
/// @file
/// The rehearsal cell on demand (docs/console.md, "Rehearsal"): the console starts the command that
/// brings up the simulated cell of the rehearsal domain when a rehearsal needs it, and stops it after it
/// has been idle for a while. The command runs as a child process group of its own (its first process
/// leads it), its output appended to a log file. It is stopped by its PID and that group only: SIGTERM
/// to the leader (`rigger-compose supervise` stops its services in order on it), SIGTERM to whatever of
/// the group outlived it, SIGKILL to the group after the stop timeout.
///
/// Pure POSIX, no DDS: the owner says at each step() whether the cell is there (a controller reads
/// recipes and a world model answers cell requests on the rehearsal domain) and whether a rehearsal
/// runs or is watched. Not thread-safe: one thread (the console's loop) calls everything.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::console {

/// How to bring the rehearsal cell up.
struct LaunchCommand {
  std::vector<std::string> argv;  ///< argv[0] without a '/': looked up in `program_dir`, then in PATH
  std::vector<std::string> env;   ///< "NAME=value", added to the console's environment
  std::string cwd;                ///< where it runs ("": the console's working directory)
  std::string log_file;           ///< its stdout and stderr, appended
  std::string program_dir;        ///< the console's own folder, where rigger-compose is installed beside it
};

struct LaunchTimes {
  std::chrono::milliseconds start_timeout{120000};  ///< from the start to the cell being there
  std::chrono::milliseconds idle_stop{120000};      ///< ready, no rehearsal running or watched: stop
  std::chrono::milliseconds stop_timeout{30000};    ///< SIGTERM, then SIGKILL to the group
};

enum class CellPhase { kIdle, kStarting, kReady, kStopping };
const char* phase_name(CellPhase phase);

/// A change of phase, for the audit log and the console's log.
struct CellChange {
  CellPhase phase = CellPhase::kIdle;  ///< the phase now
  std::string what;                    ///< "started (pid 12, log /var/...)", "ready after 4.2 s", ...
  bool failed = false;                 ///< a start that came to nothing (exit, timeout, exec error)
};

class RehearsalLauncher {
 public:
  using Clock = std::chrono::steady_clock;

  /// Makes the console a child subreaper, so that what the command leaves behind when its leader ends
  /// is still the console's to reap and to wait for.
  RehearsalLauncher(LaunchCommand command, LaunchTimes times);
  /// Stops the cell if it runs, waiting up to the stop timeout (then SIGKILL).
  ~RehearsalLauncher();
  RehearsalLauncher(const RehearsalLauncher&) = delete;
  RehearsalLauncher& operator=(const RehearsalLauncher&) = delete;

  /// Starts the command when idle (nothing when it is already starting or ready; a failed change when
  /// it is still stopping or cannot be spawned). `env`: "NAME=value" for this start only, over the
  /// command's own.
  std::optional<CellChange> start(Clock::time_point now, const std::vector<std::string>& env = {});
  /// Stops the cell for `why` and, once all of it ended, starts it again with `env` (this start only);
  /// starts it at once when idle. status() says "restart": true until it starts again.
  std::optional<CellChange> restart(Clock::time_point now, const std::vector<std::string>& env, const std::string& why);
  /// Advances the state machine: `there` — the cell is there (see above), it is ready;
  /// `busy` — a rehearsal runs or someone watches one (the idle time restarts).
  std::optional<CellChange> step(Clock::time_point now, bool there, bool busy);

  CellPhase phase() const { return phase_; }
  /// Stopping to start again (restart()).
  bool restarting() const { return restart_; }
  /// {"phase", "pid" (0: none), "log", "error" (why the last start failed, "" otherwise),
  ///  "start_timeout_s", "idle_stop_s", "restart": stopping to start again}.
  nlohmann::json status() const;
  const std::string& log_file() const { return command_.log_file; }

 private:
  /// Reaps what ended in the group; true when nothing of it is left.
  bool reap();
  CellChange begin_stop(Clock::time_point now, std::string why, bool failed);

  LaunchCommand command_;
  LaunchTimes times_;
  CellPhase phase_ = CellPhase::kIdle;
  pid_t pid_ = 0;  ///< the group's leader (and the group's id); 0: none
  bool leader_alive_ = false;
  std::string leader_end_;  ///< how the leader ended ("exited with code 1", "killed by SIGKILL")
  std::string error_;
  Clock::time_point since_{};      ///< the phase's start (starting, stopping) or the last busy time (ready)
  Clock::time_point started_at_{};
  bool killed_ = false;
  bool stop_failed_ = false;       ///< the stop ends a failed start
  std::string stop_why_;
  bool restart_ = false;               ///< start again once stopped
  std::vector<std::string> restart_env_;
};

}  // namespace rigger::console
