#include "rigger/testing/lab.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <stdexcept>

#include "rigger/testing/process.hpp"

namespace rigger::testing {
namespace {

// Kills what still runs in the lab's namespaces (by PID; they are this test's: the namespaces are named
// after it), except the PID in $1, then deletes the namespaces. Run from the source tree.
constexpr const char* kTearDown =
    "for ns in $(ip netns list | awk '{print $1}' | grep \"^$RIGGER_LAB-\" || true); do ip netns pids \"$ns\"; done |"
    " while read -r p; do [ \"$p\" = \"$1\" ] || kill -KILL \"$p\" 2>/dev/null || true; done;"
    " exec deploy/lab-hosts down";

std::string log_path(const std::string& lab, const std::string& what) {
  const std::string dir = std::string(RIGGER_BINARY_DIR) + "/test-logs";
  std::error_code ignored;
  std::filesystem::create_directories(dir, ignored);
  return dir + "/lab-" + lab + "-" + what + ".log";
}

/// Runs `script` with bash in the source tree for lab `lab`; its output on failure, "" on success.
std::string run(const std::string& lab, const std::string& what, const std::string& script) {
  ChildProcess p("/bin/bash", {"-c", "cd '" RIGGER_SOURCE_DIR "' && " + script, "lab", std::to_string(getpid())},
                 {{"RIGGER_LAB", lab}}, log_path(lab, what));
  auto status = p.wait(std::chrono::seconds(60));
  if (!status) {
    p.signal(SIGKILL);
    return what + " did not finish within 60 s:\n" + p.log();
  }
  return status->ok() ? "" : what + ": " + status->describe() + "\n" + p.log();
}

/// A process outside this one's process tree (so that ctest's kill of a timed-out test does not reach it)
/// that waits until `read_fd` gives EOF, i.e. until every holder of the write end (only this process: the
/// end is close-on-exec) closed it or died, then tears lab `lab` down.
void start_watcher(const std::string& lab, int read_fd) {
  const std::string script = "cd '" RIGGER_SOURCE_DIR "' && read -r _; " + std::string(kTearDown);
  const std::string env_lab = "RIGGER_LAB=" + lab;
  std::vector<const char*> argv{"/bin/bash", "-c", script.c_str(), "lab-watcher", "0", nullptr};
  std::vector<const char*> envp{env_lab.c_str(), "PATH=/usr/sbin:/usr/bin:/sbin:/bin", nullptr};
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error(std::string("lab watcher: fork: ") + std::strerror(errno));
  if (child == 0) {  // only async-signal-safe calls from here on
    setsid();
    if (fork() != 0) _exit(0);
    dup2(read_fd, STDIN_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    for (int fd = 3; fd < 1024; ++fd) close(fd);
    execve(argv[0], const_cast<char* const*>(argv.data()), const_cast<char* const*>(envp.data()));
    _exit(127);
  }
  int status = 0;
  waitpid(child, &status, 0);
}

}  // namespace

Lab::Lab(std::string name, const std::vector<std::string>& hosts) : name_(std::move(name)) {
  if (!std::regex_match(name_, std::regex("[a-z0-9]{1,8}")))
    throw std::invalid_argument("lab name '" + name_ + "' must be 1-8 lower-case letters or digits");
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("lab: pipe2: ") + std::strerror(errno));
  start_watcher(name_, fds[0]);
  close(fds[0]);
  watcher_fd_ = fds[1];

  std::string up = "deploy/lab-hosts down && deploy/lab-hosts up";
  for (const auto& h : hosts) up += " " + h;
  if (const auto problem = run(name_, "up", up); !problem.empty()) {
    tear_down();
    throw std::runtime_error(problem);
  }
  // "lab-hosts: host ros2 = namespace r123-ros2, eth0 10.213.0.2/24"
  std::ifstream log(log_path(name_, "up"));
  const std::regex made(R"(host (\S+) = namespace \S+, eth0 ([0-9.]+)/)");
  for (std::string line; std::getline(log, line);) {
    std::smatch m;
    if (std::regex_search(line, m, made)) addresses_[m[1]] = m[2];
  }
  for (const auto& h : hosts) {
    if (!addresses_.count(h)) {
      tear_down();
      throw std::runtime_error("lab-hosts up did not report host " + h + "'s address (" + log_path(name_, "up") + ")");
    }
  }
}

Lab::~Lab() {
  tear_down();
}

void Lab::enter(const std::string& host) {
  if (origin_ns_ < 0) origin_ns_ = open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC);
  const std::string path = "/var/run/netns/" + name_ + "-" + host;
  const int ns = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (ns < 0) throw std::runtime_error("lab: open " + path + ": " + std::strerror(errno));
  const int rc = setns(ns, CLONE_NEWNET);
  const int error = errno;
  close(ns);
  if (rc != 0) throw std::runtime_error("lab: setns " + path + ": " + std::strerror(error));
}

void Lab::leave() {
  if (origin_ns_ < 0) return;
  if (setns(origin_ns_, CLONE_NEWNET) != 0)
    teardown_problems_ += std::string("lab: could not leave the lab's namespace: ") + std::strerror(errno) + "\n";
  close(origin_ns_);
  origin_ns_ = -1;
}

const std::string& Lab::tear_down() {
  if (torn_down_) return teardown_problems_;
  torn_down_ = true;
  leave();
  teardown_problems_ += run(name_, "down", kTearDown);
  // The lab is gone: the watcher wakes, finds nothing left and ends.
  if (watcher_fd_ >= 0) close(watcher_fd_);
  watcher_fd_ = -1;
  return teardown_problems_;
}

}  // namespace rigger::testing
