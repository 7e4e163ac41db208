#include "rigger/testing/process.hpp"

#include "rigger/base/process.hpp"
#include "rigger/testing/domain.hpp"

#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace rigger::testing {

std::string ExitStatus::describe() const {
  if (exited) return "exit code " + std::to_string(code);
  return std::string("killed by ") + strsignal(signal);
}

ChildProcess::ChildProcess(const std::string& binary, const std::vector<std::string>& args,
                           const std::map<std::string, std::string>& env, const std::string& log_path,
                           std::function<void()> on_exit)
    : log_path_(log_path) {
  SpawnRequest request;
  request.path = binary.find('/') == std::string::npos ? bin_dir_path(binary) : binary;
  request.args = args;
  request.env = env;
  request.log_path = log_path;
  request.truncate_log = true;
  try {
    pid_ = spawn_process(request);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot start " + request.path + ": " + e.what());
  }

  reaper_ = std::thread([this, on_exit = std::move(on_exit)] {
    // Wait without reaping, record the end, and only then reap under the lock: signal() can never hit
    // a recycled PID that belongs to some other process.
    siginfo_t info{};
    while (waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ExitStatus s;
      s.exited = info.si_code == CLD_EXITED;
      s.code = s.exited ? info.si_status : 0;
      s.signal = s.exited ? 0 : info.si_status;
      status_ = s;
      int ignored = 0;
      waitpid(pid_, &ignored, 0);
    }
    cv_.notify_all();
    if (on_exit) on_exit();
  });
}

std::string ChildProcess::bin_dir_path(const std::string& name) { return bin_dir() + "/" + name; }

ChildProcess::~ChildProcess() {
  signal(SIGKILL);
  if (reaper_.joinable()) reaper_.join();
}

bool ChildProcess::signal(int sig) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (status_ || pid_ <= 0) return false;  // already reaped: the PID may belong to someone else now
  return ::kill(pid_, sig) == 0;
}

std::optional<ExitStatus> ChildProcess::wait(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait_for(lock, timeout, [this] { return status_.has_value(); });
  return status_;
}

bool ChildProcess::running() {
  std::lock_guard<std::mutex> lock(mutex_);
  return !status_.has_value();
}

std::string ChildProcess::log() const {
  std::ifstream in(log_path_);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto paren = text.rfind(')');  // the command name may hold spaces
  if (paren == std::string::npos) return -1;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  unsigned long utime = 0, stime = 0;
  // After ")": state is field 3; utime and stime are fields 14 and 15.
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoul(field);
    if (i == 15) stime = std::stoul(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace rigger::testing
