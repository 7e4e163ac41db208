#include "rigger/compose/process_util.hpp"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace rigger::compose {
namespace {

constexpr const char* kLockDir = "/tmp/rigger-compose";

std::string errno_text(int err) { return strerror(err); }

// Through syscall(): glibc 2.36's <sys/pidfd.h> lacks C linkage for C++ callers.
int open_pidfd(int pid) { return static_cast<int>(syscall(SYS_pidfd_open, pid, 0u)); }
int pidfd_signal(int fd, int sig) { return static_cast<int>(syscall(SYS_pidfd_send_signal, fd, sig, nullptr, 0u)); }

}  // namespace

void make_dirs(const std::string& path) {
  std::string partial;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') partial = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    partial += part + "/";
    if (mkdir(partial.c_str(), 0777) != 0 && errno != EEXIST)
      throw std::runtime_error("cannot create folder " + partial + ": " + errno_text(errno));
  }
}

DomainLock::DomainLock(std::uint32_t domain, std::string host) : domain_(domain), host_(std::move(host)) {}

DomainLock::~DomainLock() {
  if (fd_ >= 0) close(fd_);
}

std::string DomainLock::path(std::uint32_t domain, const std::string& host) {
  // Host names are [A-Za-z0-9.-] (compose_file checks them); anything else would not reach here.
  return std::string(kLockDir) + "/domain-" + std::to_string(domain) + (host.empty() ? "" : "@" + host) + ".lock";
}

bool DomainLock::try_lock(const std::string& log_dir) {
  make_dirs(kLockDir);
  const int fd = open(path(domain_, host_).c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
  if (fd < 0) throw std::runtime_error("cannot open " + path(domain_, host_) + ": " + errno_text(errno));
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    close(fd);
    return false;
  }
  const std::string content = std::to_string(getpid()) + " " + log_dir + "\n";
  if (ftruncate(fd, 0) != 0 || pwrite(fd, content.data(), content.size(), 0) != static_cast<ssize_t>(content.size())) {
    close(fd);
    throw std::runtime_error("cannot write " + path(domain_, host_) + ": " + errno_text(errno));
  }
  fd_ = fd;
  return true;
}

std::optional<LockHolder> DomainLock::holder(std::uint32_t domain, const std::string& host) {
  const int fd = open(path(domain, host).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;  // never created: nobody holds it
  // A shared lock is granted only when nobody holds the exclusive one.
  if (flock(fd, LOCK_SH | LOCK_NB) == 0) {
    close(fd);
    return std::nullopt;
  }
  char buf[4096] = {};
  const ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
  close(fd);
  LockHolder h;
  if (n > 0) {
    std::istringstream in(std::string(buf, static_cast<std::size_t>(n)));
    in >> h.pid;
    in.get();
    std::getline(in, h.log_dir);
  }
  return h;
}

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
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, request.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                     0644);
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
  if (rc != 0) throw std::runtime_error(errno_text(rc));
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

std::string self_executable() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find this executable: " + errno_text(errno));
  return std::string(buf, static_cast<std::size_t>(n));
}

std::vector<std::string> this_host_names(const std::string& configured) {
  std::vector<std::string> out;
  if (!configured.empty()) out.push_back(configured);
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) == 0 && buf[0]) {
    const std::string full(buf);
    out.push_back(full);
    const auto dot = full.find('.');
    if (dot != std::string::npos) out.push_back(full.substr(0, dot));
  }
  return out;
}

std::optional<std::string> read_text_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace rigger::compose
