#include "rehearsal_launcher.hpp"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <thread>

extern char** environ;

namespace rigger::console {

namespace {

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

std::string one_decimal(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", s);
  return text;
}

std::string how_it_ended(int status) {
  if (WIFEXITED(status)) return "exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const char* name = sigabbrev_np(WTERMSIG(status));
    return std::string("was killed by SIG") + (name ? name : std::to_string(WTERMSIG(status)).c_str());
  }
  return "ended";
}

bool executable(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(path.c_str(), X_OK) == 0;
}

}  // namespace

const char* phase_name(CellPhase phase) {
  switch (phase) {
    case CellPhase::kIdle: return "idle";
    case CellPhase::kStarting: return "starting";
    case CellPhase::kReady: return "ready";
    case CellPhase::kStopping: return "stopping";
  }
  return "idle";
}

RehearsalLauncher::RehearsalLauncher(LaunchCommand command, LaunchTimes times)
    : command_(std::move(command)), times_(times) {
  // Without it, a process of the group whose leader ended is re-parented to init, and the console could
  // neither reap it nor tell when the group is empty.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
}

RehearsalLauncher::~RehearsalLauncher() {
  if (pid_ == 0) return;
  if (leader_alive_) kill(pid_, SIGTERM);
  const auto deadline = Clock::now() + times_.stop_timeout;
  bool leftovers_told = false;
  // Shutting down: a bounded wait on this thread is what the console's stop is for.
  while (!reap()) {
    if (!leader_alive_ && !leftovers_told) {
      kill(-pid_, SIGTERM);
      leftovers_told = true;
    }
    if (Clock::now() > deadline) {
      kill(-pid_, SIGKILL);
      while (!reap()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

nlohmann::json RehearsalLauncher::status() const {
  return {{"phase", phase_name(phase_)},
          {"pid", pid_},
          {"log", command_.log_file},
          {"error", error_},
          {"start_timeout_s", seconds(times_.start_timeout)},
          {"idle_stop_s", seconds(times_.idle_stop)},
          {"restart", restart_}};
}

std::optional<CellChange> RehearsalLauncher::restart(Clock::time_point now, const std::vector<std::string>& env,
                                                     const std::string& why) {
  if (phase_ == CellPhase::kIdle) return start(now, env);
  restart_ = true;
  restart_env_ = env;
  if (phase_ == CellPhase::kStopping) return std::nullopt;  // it starts again once stopped
  return begin_stop(now, why, false);
}

std::optional<CellChange> RehearsalLauncher::start(Clock::time_point now, const std::vector<std::string>& env) {
  if (phase_ == CellPhase::kStarting || phase_ == CellPhase::kReady) return std::nullopt;
  if (phase_ == CellPhase::kStopping) {
    return CellChange{phase_, "not started: the rehearsal cell (pid " + std::to_string(pid_) + ") is still stopping",
                      true};
  }
  if (command_.argv.empty()) return CellChange{phase_, "not started: no start command is configured", true};
  error_.clear();
  std::string program = command_.argv[0];
  if (program.find('/') == std::string::npos && !command_.program_dir.empty() &&
      executable(command_.program_dir + "/" + program))
    program = command_.program_dir + "/" + program;

  // Everything the child needs is made before fork: between fork and exec only async-signal-safe calls.
  std::vector<std::string> mine = command_.env;
  mine.insert(mine.end(), env.begin(), env.end());
  std::vector<std::string> env_text;
  const auto name_of = [](const std::string& entry) { return entry.substr(0, entry.find('=')); };
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    bool replaced = false;
    for (const auto& m : mine) replaced = replaced || name_of(m) == name_of(entry);
    if (!replaced) env_text.push_back(entry);
  }
  for (std::size_t i = 0; i < mine.size(); ++i) {  // this start's entries over the command's own
    bool later = false;
    for (std::size_t j = i + 1; j < mine.size(); ++j) later = later || name_of(mine[j]) == name_of(mine[i]);
    if (!later) env_text.push_back(mine[i]);
  }
  std::vector<char*> envp, argv;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = command_.argv;
  args[0] = program;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int log_fd = open(command_.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    error_ = "cannot open the log " + command_.log_file + ": " + strerror(errno);
    return CellChange{phase_, "not started: " + error_, true};
  }
  const std::string banner = "--- the console starts the rehearsal cell: " + program + "\n";
  (void)!write(log_fd, banner.data(), banner.size());
  const std::string cant = "cannot run " + program + ": ";
  const char* cwd = command_.cwd.empty() ? nullptr : command_.cwd.c_str();

  const pid_t pid = fork();
  if (pid < 0) {
    error_ = std::string("fork: ") + strerror(errno);
    close(log_fd);
    return CellChange{phase_, "not started: " + error_, true};
  }
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // a console killed outright still stops the cell's supervisor
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);  // the console's threads block the signals its loop waits for
    for (const int s : {SIGINT, SIGTERM, SIGPIPE, SIGHUP}) signal(s, SIG_DFL);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(log_fd, 1);
    dup2(log_fd, 2);
    if (cwd != nullptr && chdir(cwd) != 0) {
      (void)!write(2, cant.data(), cant.size());
      (void)!write(2, "cannot enter its folder\n", 24);
      _exit(127);
    }
    execvpe(argv[0], argv.data(), envp.data());
    (void)!write(2, cant.data(), cant.size());
    const char* why = strerror(errno);
    (void)!write(2, why, strlen(why));
    (void)!write(2, "\n", 1);
    _exit(127);
  }
  setpgid(pid, pid);  // also here: the group exists before either side goes on
  close(log_fd);
  pid_ = pid;
  leader_alive_ = true;
  leader_end_.clear();
  killed_ = false;
  phase_ = CellPhase::kStarting;
  since_ = started_at_ = now;
  return CellChange{phase_, "started (pid " + std::to_string(pid) + ", log " + command_.log_file + ")", false};
}

bool RehearsalLauncher::reap() {
  if (pid_ == 0) return true;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(-pid_, &status, WNOHANG);
    if (r > 0) {
      if (r == pid_) {
        leader_alive_ = false;
        leader_end_ = how_it_ended(status);
      }
      continue;
    }
    if (r < 0 && errno == EINTR) continue;
    // ECHILD: no process of the group is left (as the subreaper, the console is every one's parent).
    return r < 0 && errno == ECHILD;
  }
}

CellChange RehearsalLauncher::begin_stop(Clock::time_point now, std::string why, bool failed) {
  if (leader_alive_) kill(pid_, SIGTERM);
  else kill(-pid_, SIGTERM);
  phase_ = CellPhase::kStopping;
  since_ = now;
  stop_failed_ = failed;
  stop_why_ = why;
  if (failed) error_ = why + "; see " + command_.log_file;
  return CellChange{phase_, "stopping (pid " + std::to_string(pid_) + "): " + why, failed};
}

std::optional<CellChange> RehearsalLauncher::step(Clock::time_point now, bool there, bool busy) {
  if (phase_ == CellPhase::kIdle) return std::nullopt;
  const bool gone = reap();
  const std::string pid = std::to_string(pid_);
  switch (phase_) {
    case CellPhase::kStarting:
      if (!leader_alive_) {
        const std::string why = "the start command " + leader_end_ + " before the rehearsal cell was there";
        if (!gone) return begin_stop(now, why, true);
        error_ = why + "; see " + command_.log_file;
        phase_ = CellPhase::kIdle;
        pid_ = 0;
        return CellChange{phase_, error_, true};
      }
      if (there) {
        phase_ = CellPhase::kReady;
        since_ = now;
        return CellChange{phase_, "ready after " + one_decimal(seconds(now - started_at_)) + " s (pid " + pid + ")",
                          false};
      }
      if (now - started_at_ >= times_.start_timeout)
        return begin_stop(now,
                          "the rehearsal cell (a task controller reading recipes, a world model answering cell "
                          "requests) was not there within " +
                              one_decimal(seconds(times_.start_timeout)) + " s of the start",
                          true);
      return std::nullopt;
    case CellPhase::kReady:
      if (!leader_alive_) return begin_stop(now, "the rehearsal cell's command " + leader_end_, false);
      if (busy) {
        since_ = now;
        return std::nullopt;
      }
      if (now - since_ >= times_.idle_stop)
        return begin_stop(now, "idle for " + one_decimal(seconds(now - since_)) + " s", false);
      return std::nullopt;
    case CellPhase::kStopping:
      if (gone) {
        phase_ = CellPhase::kIdle;
        pid_ = 0;
        CellChange stopped{phase_,
                           "stopped (pid " + pid + ", " + stop_why_ + ") after " +
                               one_decimal(seconds(now - since_)) + " s" + (killed_ ? " (SIGKILL)" : ""),
                           stop_failed_};
        if (!restart_) return stopped;
        restart_ = false;
        const auto again = start(now, restart_env_);
        if (!again) return stopped;
        return CellChange{again->phase, stopped.what + "; " + again->what, again->failed};
      }
      if (!leader_alive_) kill(-pid_, SIGTERM);  // what outlived the leader
      if (!killed_ && now - since_ >= times_.stop_timeout) {
        kill(-pid_, SIGKILL);
        killed_ = true;
      }
      return std::nullopt;
    case CellPhase::kIdle:
      break;
  }
  return std::nullopt;
}

}  // namespace rigger::console
