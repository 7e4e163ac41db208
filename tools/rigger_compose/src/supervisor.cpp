#include "rigger/compose/supervisor.hpp"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <thread>

#include "rigger/compose/process_util.hpp"
#include "rigger/compose/status_file.hpp"
#include "rigger/compose/supervision.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::compose {
namespace {

using Level = SupervisionCommand::Level;

// Progress for the `up` command that waits on the other end of a pipe. It may have gone away (Ctrl-C):
// a failed write just closes our end; SIGPIPE is ignored in the supervisor.
class Notifier {
 public:
  explicit Notifier(int fd) : fd_(fd) {}
  ~Notifier() { close_fd(); }
  Notifier(const Notifier&) = delete;
  Notifier& operator=(const Notifier&) = delete;

  void line(const std::string& text) {
    if (fd_ < 0) return;
    const std::string out = text + "\n";
    std::size_t done = 0;
    while (done < out.size()) {
      const ssize_t n = write(fd_, out.data() + done, out.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        close_fd();
        return;
      }
      done += static_cast<std::size_t>(n);
    }
  }
  void close_fd() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

std::string local_time_text() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S%z", &tm);
  return buf;
}

void append_line(const std::string& path, const std::string& text) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return;
  const std::string out = text + "\n";
  (void)!write(fd, out.data(), out.size());
  close(fd);
}

ExitInfo exit_info(int status) {
  ExitInfo info;
  if (WIFEXITED(status)) {
    info.exited = true;
    info.code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    info.signal = WTERMSIG(status);
  }
  return info;
}

// Waits on the signalfd, the control FIFO and a wake-up pipe, and turns each event into work posted to
// the event loop: the DDS waitset cannot wait on file descriptors, and all decisions (and every kill())
// stay on the loop's thread.
class IoThread {
 public:
  struct Handlers {
    std::function<void()> child_ended;
    std::function<void(int signal)> stop_signal;
    std::function<void(const std::string& line)> request;
  };

  IoThread(int signal_fd, int fifo_fd, Handlers handlers)
      : signal_fd_(signal_fd), fifo_fd_(fifo_fd), handlers_(std::move(handlers)) {
    if (pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0) throw std::runtime_error(std::string("pipe2: ") + strerror(errno));
    thread_ = std::thread([this] { run(); });
  }
  ~IoThread() {
    (void)!write(wake_[1], "x", 1);
    thread_.join();
    close(wake_[0]);
    close(wake_[1]);
  }
  IoThread(const IoThread&) = delete;
  IoThread& operator=(const IoThread&) = delete;

 private:
  void run() {
    std::string pending;
    for (;;) {
      pollfd fds[3] = {{wake_[0], POLLIN, 0}, {signal_fd_, POLLIN, 0}, {fifo_fd_, POLLIN, 0}};
      const int n = poll(fds, fifo_fd_ >= 0 ? 3 : 2, -1);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 || (fds[0].revents & POLLIN)) return;
      if (fds[1].revents & POLLIN) {
        signalfd_siginfo info{};
        while (read(signal_fd_, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
          if (info.ssi_signo == SIGCHLD)
            handlers_.child_ended();
          else
            handlers_.stop_signal(static_cast<int>(info.ssi_signo));
        }
      }
      if (fifo_fd_ >= 0 && (fds[2].revents & POLLIN)) {
        char buf[512];
        ssize_t got;
        while ((got = read(fifo_fd_, buf, sizeof buf)) > 0) pending.append(buf, static_cast<std::size_t>(got));
        std::size_t eol;
        while ((eol = pending.find('\n')) != std::string::npos) {
          handlers_.request(pending.substr(0, eol));
          pending.erase(0, eol + 1);
        }
        if (pending.size() > 4096) pending.clear();  // a writer that never ends its line
      }
    }
  }

  int signal_fd_;
  int fifo_fd_;
  Handlers handlers_;
  int wake_[2] = {-1, -1};
  std::thread thread_;
};

class SupervisorProcess {
 public:
  SupervisorProcess(const ComposeFile& file, const SupervisorOptions& options, const Logger& log)
      : file_(file), options_(options), log_(log), layout_(file.log_dir), notify_(options.notify_fd) {}

  int run() {
    try {
      make_dirs(layout_.log_dir);
    } catch (const std::exception& e) {
      return fail_early(e.what(), 1);
    }
    DomainLock lock(file_.domain, options_.host);
    try {
      if (!lock.try_lock(layout_.log_dir)) {
        const auto holder = DomainLock::holder(file_.domain, options_.host);
        return fail_early(
            "a supervisor already runs for DDS domain " + std::to_string(file_.domain) +
                (holder ? " (pid " + std::to_string(holder->pid) + ", log dir " + holder->log_dir + ")" : "") +
                ": stop it with `rigger-compose down` first",
            1);
      }
    } catch (const std::exception& e) {
      return fail_early(e.what(), 1);
    }
    std::vector<Supervision::Entry> plan;
    try {
      plan = make_plan(file_, options_.services, options_.this_host_names);
    } catch (const std::exception& e) {
      return fail_early(e.what(), 2);
    }

    // Signals become events on a signalfd. They must be blocked before any other thread (Cyclone's
    // included) exists, so that every thread inherits the mask and none of them takes the signal.
    sigset_t set;
    sigemptyset(&set);
    for (int sig : {SIGCHLD, SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, sig);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    signal(SIGPIPE, SIG_IGN);
    const int signal_fd = signalfd(-1, &set, SFD_CLOEXEC | SFD_NONBLOCK);
    if (signal_fd < 0) return fail_early(std::string("signalfd: ") + strerror(errno), 1);

    unlink(layout_.control_fifo().c_str());
    int fifo_fd = -1;
    if (mkfifo(layout_.control_fifo().c_str(), 0600) == 0) {
      // Read-write, so the FIFO never reports end-of-file when a `restart` command closes its end.
      fifo_fd = open(layout_.control_fifo().c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    }
    if (fifo_fd < 0)
      log_->warn("control fifo unavailable path={} error={}: restart requests disabled", layout_.control_fifo(),
                 strerror(errno));
    append_line(layout_.pid_file() + ".tmp", std::to_string(getpid()));
    std::rename((layout_.pid_file() + ".tmp").c_str(), layout_.pid_file().c_str());

    int rc = 1;
    try {
      rc = supervise(plan, signal_fd, fifo_fd);
    } catch (const std::exception& e) {
      // Setup failed (e.g. DDS): nothing was spawned yet, or stop() below already ran.
      log_->critical("fatal: {}", e.what());
      notify_.line("E supervisor: " + std::string(e.what()));
    }
    unlink(layout_.pid_file().c_str());
    unlink(layout_.control_fifo().c_str());
    if (fifo_fd >= 0) close(fifo_fd);
    close(signal_fd);
    return rc;
  }

 private:
  int fail_early(const std::string& reason, int code) {
    log_->error("not starting: {}", reason);
    notify_.line("E " + reason);
    return code;
  }

  int supervise(const std::vector<Supervision::Entry>& plan, int signal_fd, int fifo_fd) {
    if (!file_.dds_config.empty()) setenv("CYCLONEDDS_URI", file_.dds_uri().c_str(), 1);
    dds::Participant participant(file_.domain);
    dds::EventLoop loop(participant);
    service::ServiceDirectory directory(participant);
    Supervision supervision(plan);
    loop_ = &loop;
    supervision_ = &supervision;
    directory_ = &directory;

    loop.on_data(directory.reader(), [this] {
      directory_->update();
      feed_readiness();
      apply();
    });
    IoThread io(signal_fd, fifo_fd,
                {[&loop, this] { loop.post([this] { reap(); }); },
                 [&loop, this](int sig) {
                   loop.post([this, sig] {
                     log_->info("signal received signal={}", strsignal(sig));
                     supervision_->stop(std::string("signal ") + strsignal(sig), Clock::now());
                     apply();
                   });
                 },
                 [&loop, this](const std::string& line) { loop.post([this, line] { handle_request(line); }); }});

    log_->info("supervisor started pid={} domain={} file={} log_dir={} services={}", getpid(), file_.domain, file_.path,
               layout_.log_dir, plan.size());
    supervision.begin(Clock::now());
    apply();
    if (supervision.phase() != Phase::kDone) loop.run();
    reap();  // children that ended while the loop was stopping
    write_status();
    log_->info("supervisor exiting result={}", supervision.failed() ? "bring-up failed" : "clean stop");
    loop_ = nullptr;
    supervision_ = nullptr;
    directory_ = nullptr;
    return supervision.failed() ? 1 : 0;
  }

  void feed_readiness() {
    const auto now = Clock::now();
    const auto& known = directory_->services();
    for (const auto& s : supervision_->services()) {
      auto it = known.find(s.name());
      const bool ready = it != known.end() && it->second.alive && it->second.status == service::ServiceStatus::kReady;
      if (ready)
        supervision_->announced_ready(s.name(), it->second.pid, now);
      else if (!s.local)
        supervision_->announced_lost(s.name(), now);
    }
  }

  void reap() {
    if (!supervision_) return;
    int status = 0;
    pid_t pid;
    while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
      const auto info = exit_info(status);
      log_->debug("child ended pid={} how={}", pid, info.describe());
      supervision_->exited(pid, info, Clock::now());
    }
    apply();
  }

  void handle_request(const std::string& line) {
    const std::string verb = "restart ";
    if (line.compare(0, verb.size(), verb) != 0) {
      log_->warn("unknown request line={}", line);
      return;
    }
    const std::string service = line.substr(verb.size());
    log_->info("request restart service={}", service);
    const std::string error = supervision_->restart(service, Clock::now());
    if (!error.empty()) log_->error("restart refused service={} reason={}", service, error);
    apply();
  }

  // Carries out the supervision's commands (which may produce more), then publishes the new state and
  // arms the timer for the next deadline.
  void apply() {
    if (!supervision_) return;
    for (auto commands = supervision_->take_commands(); !commands.empty(); commands = supervision_->take_commands()) {
      for (const auto& c : commands) execute(c);
    }
    write_status();
    if (!ready_sent_ && supervision_->phase() == Phase::kRunning) {
      ready_sent_ = true;
      notify_.line("OK");
      notify_.close_fd();
    }
    if (timer_) loop_->cancel(*timer_);
    timer_.reset();
    if (const auto deadline = supervision_->next_deadline()) {
      const auto delay = std::max(Clock::duration::zero(), *deadline - Clock::now());
      timer_ = loop_->after(delay, [this] {
        timer_.reset();
        supervision_->advance(Clock::now());
        apply();
      });
    }
    if (supervision_->phase() == Phase::kDone) loop_->stop();
  }

  void execute(const SupervisionCommand& c) {
    switch (c.kind) {
      case SupervisionCommand::Kind::kReport:
        switch (c.level) {
          case Level::kDetail: log_->info("{}", c.text); break;
          case Level::kInfo:
            log_->info("{}", c.text);
            notify_.line("I " + c.text);
            break;
          case Level::kWarn:
            log_->warn("{}", c.text);
            notify_.line("W " + c.text);
            break;
          case Level::kError:
            log_->error("{}", c.text);
            notify_.line("E " + c.text);
            break;
        }
        break;
      case SupervisionCommand::Kind::kSignal:
        // The supervision only names PIDs it spawned and has not seen reaped; reaping happens on this
        // thread, so the PID cannot have been recycled in between.
        if (c.pid > 0 && kill(c.pid, c.signal) != 0)
          log_->warn("signal failed service={} pid={} signal={} error={}", c.service, c.pid, c.signal, strerror(errno));
        break;
      case SupervisionCommand::Kind::kSpawn: spawn(c.service); break;
    }
  }

  void spawn(const std::string& name) {
    const auto* s = supervision_->find(name);
    if (!s) return;
    const ServiceDef& def = *s->def;
    SpawnRequest req;
    req.path = def.binary;
    req.args = {"--id", def.name, "--domain", std::to_string(file_.domain)};
    if (!def.config.empty()) {
      req.args.push_back("--config");
      req.args.push_back(def.config);
    }
    req.args.insert(req.args.end(), def.args.begin(), def.args.end());
    req.env = def.env;
    req.env["RIGGER_DOMAIN"] = std::to_string(file_.domain);
    if (!file_.dds_config.empty()) req.env["CYCLONEDDS_URI"] = file_.dds_uri();
    req.log_path = layout_.service_log(name);
    req.cwd = file_.root;
    // A Ctrl-C meant for a foreground supervisor must not bypass the stop order; in its caller's group,
    // the caller ends them with it (SupervisorOptions::services_in_group).
    req.new_process_group = !options_.services_in_group;
    std::string command_line = req.path;
    for (const auto& a : req.args) command_line += " " + a;
    append_line(req.log_path, "===== rigger-compose " + local_time_text() + ": starting " + name +
                                  (s->restarts ? " (restart #" + std::to_string(s->restarts) + ")" : "") + ": " +
                                  command_line);
    try {
      const int pid = spawn_process(req);
      log_->info("spawned service={} pid={} command={}", name, pid, command_line);
      supervision_->spawned(name, pid, Clock::now());
      feed_readiness();
    } catch (const std::exception& e) {
      append_line(req.log_path, "===== rigger-compose: could not start: " + std::string(e.what()));
      supervision_->spawn_failed(name, file_.display_path(def.binary) + ": " + e.what(), Clock::now());
    }
  }

  void write_status() {
    if (!supervision_) return;
    auto st = make_status(*supervision_, Clock::now(), unix_now_ms());
    st.supervisor_pid = getpid();
    st.domain = file_.domain;
    st.compose_file = file_.path;
    st.log_dir = layout_.log_dir;
    if (!write_status_file(layout_.status_file(), st))
      log_->warn("cannot write status file path={}", layout_.status_file());
  }

  const ComposeFile& file_;
  const SupervisorOptions& options_;
  Logger log_;
  LogLayout layout_;
  Notifier notify_;
  dds::EventLoop* loop_ = nullptr;
  Supervision* supervision_ = nullptr;
  service::ServiceDirectory* directory_ = nullptr;
  std::optional<dds::EventLoop::TimerId> timer_;
  bool ready_sent_ = false;
};

}  // namespace

int run_supervisor(const ComposeFile& file, const SupervisorOptions& options, const Logger& log) {
  SupervisorProcess process(file, options, log);
  return process.run();
}

}  // namespace rigger::compose
