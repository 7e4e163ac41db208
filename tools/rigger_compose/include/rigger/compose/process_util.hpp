#pragma once
/// @file
/// The operating-system side of rigger-compose: where its files live, the per-domain supervisor lock,
/// the names of this host. Starting and watching processes is rigger/base/process.hpp.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rigger/base/process.hpp"  // spawn_process, wait_for_exit, process_alive, send_signal

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

/// This executable's path (/proc/self/exe).
std::string self_executable();
/// The names this machine answers to for `host:` placement: `configured` (if non-empty) and the host
/// name, short and full.
std::vector<std::string> this_host_names(const std::string& configured);

/// Reads a whole file; nullopt when it cannot be read.
std::optional<std::string> read_text_file(const std::string& path);

}  // namespace rigger::compose
