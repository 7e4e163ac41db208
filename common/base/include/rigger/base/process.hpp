#pragma once
/// @file
/// Starting a process (posix_spawn) and watching one that need not be our child (pidfd): one way to do
/// it for the supervisor (rigger-compose) and the test harness.

#include <chrono>
#include <map>
#include <string>
#include <vector>

namespace rigger {

/// How to start a process.
struct SpawnRequest {
  std::string path;                        ///< executable
  std::vector<std::string> args;           ///< arguments after argv[0]
  std::map<std::string, std::string> env;  ///< added to (or replacing in) this process's environment
  std::string log_path;                    ///< stdout and stderr go here; empty: inherited
  bool truncate_log = false;               ///< start log_path empty rather than append to it
  std::string cwd;                         ///< working directory; empty: inherited
  bool new_session = false;                ///< setsid(): no controlling terminal, own session
  bool new_process_group = false;          ///< own process group (a terminal's Ctrl-C does not reach it)
  int pass_fd = -1;                        ///< when >= 0, becomes fd 3 in the child
};

/// Starts the process with default signal dispositions, no blocked signals, stdin from /dev/null
/// (unless no log_path is given), and every other descriptor closed. Returns its PID.
/// @throws std::runtime_error with the reason (e.g. "No such file or directory").
int spawn_process(const SpawnRequest& request);

/// Waits until process `pid` (not necessarily our child) has ended, at most `timeout`.
/// Returns true when it ended (or never existed).
bool wait_for_exit(int pid, std::chrono::milliseconds timeout);
/// True while `pid` exists and is not a zombie.
bool process_alive(int pid);
/// Sends `sig` to `pid` through a pidfd when possible. Returns false when the process is gone.
bool send_signal(int pid, int sig);

}  // namespace rigger
