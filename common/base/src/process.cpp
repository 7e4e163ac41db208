#include "rigger/base/process.hpp"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <string.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>

extern char** environ;

namespace rigger {
namespace {

// Through syscall(): glibc 2.36's <sys/pidfd.h> lacks C linkage for C++ callers.
int open_pidfd(int pid) { return static_cast<int>(syscall(SYS_pidfd_open, pid, 0u)); }
int pidfd_signal(int fd, int sig) { return static_cast<int>(syscall(SYS_pidfd_send_signal, fd, sig, nullptr, 0u)); }

}  // namespace

int spawn_process(const SpawnRequest& request) {
  std::vector<std::string> argv_store{request.path};
  argv_store.insert(argv_store.end(), request.args.begin(), request.args.end());
  std::vector<char*> argv;
  for (auto& a : argv_store) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::map<std::string, std::string> merged;
  for (char** e = environ; *e; ++e) {
    const std::string kv(*e);
    const auto eq = kv.find('=');
    if (eq != std::string::npos) merged[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  for (const auto& [k, v] : request.env) merged[k] = v;
  std::vector<std::string> env_store;
  for (const auto& [k, v] : merged) env_store.push_back(k + "=" + v);
  std::vector<char*> envp;
  for (auto& e : env_store) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (!request.log_path.empty()) {
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    const int mode = request.truncate_log ? O_TRUNC : O_APPEND;
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, request.log_path.c_str(), O_WRONLY | O_CREAT | mode, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  }
  int first_closed = 3;
  if (request.pass_fd >= 0) {
    posix_spawn_file_actions_adddup2(&actions, request.pass_fd, 3);
    first_closed = 4;
  }
  // Descriptors of the supervisor (DDS sockets, the lock, the control FIFO) must not leak into services.
  posix_spawn_file_actions_addclosefrom_np(&actions, first_closed);
  if (!request.cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, request.cwd.c_str());

  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGCHLD, SIGPIPE, SIGUSR1, SIGUSR2}) sigaddset(&defaults, sig);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  short flags = POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF;
  if (request.new_session)
    flags |= POSIX_SPAWN_SETSID;
  else if (request.new_process_group) {
    flags |= POSIX_SPAWN_SETPGROUP;
    posix_spawnattr_setpgroup(&attr, 0);
  }
  posix_spawnattr_setflags(&attr, flags);

  pid_t pid = -1;
  const int rc = posix_spawn(&pid, request.path.c_str(), &actions, &attr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw std::runtime_error(strerror(rc));
  return pid;
}

bool wait_for_exit(int pid, std::chrono::milliseconds timeout) {
  const int fd = open_pidfd(pid);
  if (fd < 0) return errno == ESRCH;
  pollfd p{fd, POLLIN, 0};
  int rc;
  do {
    rc = poll(&p, 1, static_cast<int>(timeout.count()));
  } while (rc < 0 && errno == EINTR);
  close(fd);
  return rc > 0;
}

bool process_alive(int pid) {
  if (pid <= 0) return false;
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  if (!in) return false;
  std::string line;
  std::getline(in, line);
  // "pid (comm) S ...": the state follows the last ')' (comm may contain spaces and parentheses).
  const auto close_paren = line.rfind(')');
  if (close_paren == std::string::npos || close_paren + 2 >= line.size()) return false;
  const char state = line[close_paren + 2];
  return state != 'Z' && state != 'X';
}

bool send_signal(int pid, int sig) {
  const int fd = open_pidfd(pid);
  if (fd < 0) return false;
  const bool ok = pidfd_signal(fd, sig) == 0;
  close(fd);
  return ok;
}

}  // namespace rigger
