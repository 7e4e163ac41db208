#pragma once
/// @file
/// The operating-system side of rigger-compose: where its files live, the per-domain supervisor lock,
/// starting processes (posix_spawn), and waiting for a process that is not our child (pidfd).

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rigger::compose {

/// The files of one deployment in its log folder.
struct LogLayout {
  explicit LogLayout(std::string dir) : log_dir(std::move(dir)) {}
  std::string log_dir;
  std::string pid_file() const { return log_dir + "/supervisor.pid"; }
  std::string supervisor_log() const { return log_dir + "/supervisor.log"; }
  std::string status_file() const { return log_dir + "/status.json"; }
  std::string control_fifo() const { return log_dir + "/control"; }
  std::string service_log(const std::string& service) const { return log_dir + "/" + service + ".log"; }
};

/// Creates `path` and its parents. @throws std::runtime_error naming the folder that failed.
void make_dirs(const std::string& path);

/// Who holds a domain's supervisor lock.
struct LockHolder {
  int pid = 0;
  std::string log_dir;
};

/// One supervisor per DDS domain and host: an flock on /tmp/rigger-compose/domain-<d>.lock (or
/// domain-<d>@<host>.lock when the host's name was given with --host or $RIGGER_HOST: several hosts
/// that share one file system, such as network namespaces on one machine, each run their own), held for
/// the supervisor's life and released by the kernel when it dies, however it dies.
class DomainLock {
 public:
  /// `host`: the explicit host name, or empty for the machine itself.
  explicit DomainLock(std::uint32_t domain, std::string host = {});
  ~DomainLock();
  DomainLock(const DomainLock&) = delete;
  DomainLock& operator=(const DomainLock&) = delete;

  /// Takes the lock if free and records `log_dir` and this process's PID in it.
  /// @throws std::runtime_error when the lock file cannot be opened.
  bool try_lock(const std::string& log_dir);
  /// The current holder, or nullopt when nobody holds the lock.
  static std::optional<LockHolder> holder(std::uint32_t domain, const std::string& host = {});
  static std::string path(std::uint32_t domain, const std::string& host = {});

 private:
  std::uint32_t domain_;
  std::string host_;
  int fd_ = -1;
};

/// How to start a process.
struct SpawnRequest {
  std::string path;                        ///< executable
  std::vector<std::string> args;           ///< arguments after argv[0]
  std::map<std::string, std::string> env;  ///< added to (or replacing in) this process's environment
  std::string log_path;                    ///< stdout and stderr appended here; empty: inherited
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

/// This executable's path (/proc/self/exe).
std::string self_executable();
/// The names this machine answers to for `host:` placement: `configured` (if non-empty) and the host
/// name, short and full.
std::vector<std::string> this_host_names(const std::string& configured);

/// Reads a whole file; nullopt when it cannot be read.
std::optional<std::string> read_text_file(const std::string& path);

}  // namespace rigger::compose
