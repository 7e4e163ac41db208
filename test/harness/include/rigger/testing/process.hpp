#pragma once
/// @file
/// A child process started by a test: its stdout and stderr go to a log file, it is signalled and
/// reaped by PID, and a forgotten one is killed when the handle dies (only processes we started).

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace rigger::testing {

/// `s` as one word of a POSIX shell command: in single quotes, each `'` in it written `'\''`.
std::string shell_quoted(const std::string& s);

/// How a child ended.
struct ExitStatus {
  bool exited = false;  ///< true: exit(code); false: killed by `signal`
  int code = 0;
  int signal = 0;
  bool ok() const { return exited && code == 0; }
  std::string describe() const;
};

class ChildProcess {
 public:
  /// Starts `binary args...` (a bare name is looked up in bin_dir()) with `env` added to this process's
  /// environment; stdout and stderr go to `log_path`. `on_exit` runs on a private thread when the child
  /// ends. @throws std::runtime_error when it cannot be started.
  ChildProcess(const std::string& binary, const std::vector<std::string>& args,
               const std::map<std::string, std::string>& env, const std::string& log_path,
               std::function<void()> on_exit = {});
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  /// Kills the child with SIGKILL if it still runs, and reaps it.
  ~ChildProcess();

  pid_t pid() const { return pid_; }
  const std::string& log_path() const { return log_path_; }
  /// Sends `sig` to the child, unless it already ended. Returns whether it was sent.
  bool signal(int sig);
  /// Waits until the child ends or `timeout`; returns its status, or nullopt on timeout.
  std::optional<ExitStatus> wait(std::chrono::milliseconds timeout);
  bool running();
  /// The log file's content.
  std::string log() const;

 private:
  static std::string bin_dir_path(const std::string& name);

  pid_t pid_ = -1;
  std::string log_path_;
  std::thread reaper_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<ExitStatus> status_;
};

/// utime + stime of process `pid` in seconds (/proc/PID/stat), or a negative value when /proc cannot be read.
double cpu_seconds(pid_t pid);

}  // namespace rigger::testing
