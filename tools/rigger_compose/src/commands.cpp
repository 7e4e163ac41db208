#include "rigger/compose/commands.hpp"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <deque>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>

#include "rigger/base/bounded_json.hpp"
#include "rigger/base/install.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/compose/compose_file.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/security.hpp"
#include "rigger/compose/start_order.hpp"
#include "rigger/compose/status_file.hpp"
#include "rigger/compose/supervision.hpp"
#include "rigger/compose/supervisor.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/service_state.hpp"

namespace rigger::compose {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;
constexpr auto kSupervisorExitMargin = std::chrono::seconds(10);

struct GlobalOptions {
  std::string file;  ///< empty: the installation's deploy/compose.yaml (rigger/base/install.hpp)
  std::optional<std::uint32_t> domain;
  std::string host;
  bool secure = false;  ///< --secure: DDS Security (security.hpp)
};

// Raised by commands for a clear message and an exit code; caught once in run_cli.
struct CommandError {
  std::string message;
  int code;
};

[[noreturn]] void fail(const std::string& message, int code = kExitFailure) { throw CommandError{message, code}; }

ComposeFile load(const GlobalOptions& g) {
  ParseOptions opt;
  opt.domain = g.domain;
  // Without a bin_dir in the file, the services are the ones beside this rigger-compose (build/bin or
  // <prefix>/bin): an installed tree runs its own binaries wherever it was moved.
  opt.default_bin_dir = executable_path().parent_path().string();
  ComposeFile file = load_compose(g.file.empty() ? find_data_path("deploy/compose.yaml").path.string() : g.file, opt);
  if (g.secure) {
    try {
      apply_security(file, default_security_dir());
    } catch (const std::runtime_error& e) {
      fail(e.what(), kExitUsage);
    }
  }
  return file;
}

std::string host_option(const GlobalOptions& g) {
  const char* env = std::getenv("RIGGER_HOST");
  const std::string host = !g.host.empty() ? g.host : env ? env : "";
  // It names a lock file and is matched against `host:`: a host name, nothing else.
  const bool valid = host.size() <= 253 && std::all_of(host.begin(), host.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_';
  });
  if (!valid) fail("--host / $RIGGER_HOST '" + host + "' is not a host name (letters, digits, '-', '.', '_')", kExitUsage);
  return host;
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string format_uptime(std::int64_t ms) {
  if (ms < 0) return "-";
  const std::int64_t s = ms / 1000;
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%llds", static_cast<long long>(s));
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%lldm%02llds", static_cast<long long>(s / 60), static_cast<long long>(s % 60));
  else
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", static_cast<long long>(s / 3600),
                  static_cast<long long>((s / 60) % 60));
  return buf;
}

void use_dds_config(const ComposeFile& file) {
  if (!file.dds_config.empty()) setenv("CYCLONEDDS_URI", file.dds_uri().c_str(), 1);
}

// Services whose supervisor died without stopping them (SIGKILL, crash): they are still listed with
// their PIDs in its last status file. Stopped like the supervisor would, in reverse start order, after
// checking that each PID still runs that service (its command line has `--id <name>`), so a recycled
// PID is never signalled. Returns how many were found.
int stop_orphans(const ComposeFile& file, const std::string& log_dir) {
  const auto st = read_status_file(LogLayout(log_dir).status_file());
  if (!st) return 0;
  int found = 0;
  for (auto it = st->services.rbegin(); it != st->services.rend(); ++it) {
    if (!it->local || it->pid <= 0 || !process_alive(it->pid)) continue;
    const auto cmdline = read_text_file("/proc/" + std::to_string(it->pid) + "/cmdline").value_or("");
    if (cmdline.find(std::string("--id") + '\0' + it->name + '\0') == std::string::npos) continue;
    ++found;
    const auto* def = file.find(it->name);
    const auto timeout = def ? def->stop_timeout : std::chrono::milliseconds(5000);
    std::printf("  %s (pid %d) outlived its supervisor: SIGINT\n", it->name.c_str(), it->pid);
    std::fflush(stdout);
    send_signal(it->pid, SIGINT);
    if (!wait_for_exit(it->pid, timeout)) {
      std::printf("  %s (pid %d) did not stop within %.1f s: SIGKILL\n", it->name.c_str(), it->pid,
                  std::chrono::duration<double>(timeout).count());
      send_signal(it->pid, SIGKILL);
      wait_for_exit(it->pid, std::chrono::milliseconds(2000));
    }
  }
  return found;
}

// ---------------------------------------------------------------------------------------------- up

// Everything `up` checks before it starts anything, so that a missing binary or configuration is
// reported at once, all together, and nothing is left running.
std::vector<std::string> preflight(const ComposeFile& file, const std::vector<Supervision::Entry>& plan) {
  std::vector<std::string> problems;
  if (!file.dds_config.empty() && access(file.dds_config.c_str(), R_OK) != 0)
    problems.push_back("dds.config " + file.display_path(file.dds_config) + " not found");
  for (const auto& e : plan) {
    if (!e.local) continue;
    const ServiceDef& s = *e.def;
    struct stat st {};
    if (stat(s.binary.c_str(), &st) != 0) {
      problems.push_back("service " + s.name + ": binary " + file.display_path(s.binary) +
                         " not found — not built yet?");
    } else if (!S_ISREG(st.st_mode) || access(s.binary.c_str(), X_OK) != 0) {
      problems.push_back("service " + s.name + ": binary " + file.display_path(s.binary) +
                         " is not an executable file");
    }
    if (!s.config.empty() && access(s.config.c_str(), R_OK) != 0)
      problems.push_back("service " + s.name + ": config " + file.display_path(s.config) + " not found");
  }
  return problems;
}

int up(const GlobalOptions& g, const std::vector<std::string>& services) {
  const auto started = Clock::now();
  const ComposeFile file = load(g);
  const auto hosts = this_host_names(host_option(g));
  std::vector<Supervision::Entry> plan;
  try {
    plan = make_plan(file, services, hosts);
  } catch (const std::invalid_argument& e) {
    fail(e.what(), kExitUsage);
  }
  std::size_t local = 0;
  for (const auto& e : plan) local += e.local ? 1 : 0;

  // Services placed elsewhere are started there, from the same file: DDS discovery joins the hosts.
  std::set<std::string> in_plan;
  for (const auto& e : plan) in_plan.insert(e.def->name);
  for (const auto& s : file.services) {
    if (is_local_host(s.host, hosts)) continue;
    if (!services.empty() && !in_plan.count(s.name)) continue;
    std::printf("  %s runs on host %s: start it there with the same file (rigger-compose --host %s up)%s\n",
                s.name.c_str(), s.host.c_str(), s.host.c_str(),
                in_plan.count(s.name) ? "; waiting for it to be READY" : "");
  }
  if (local == 0)
    fail("no service of " + file.path + " is placed on this host (" + (hosts.empty() ? "?" : hosts[0]) + ")");

  const auto problems = preflight(file, plan);
  if (!problems.empty()) {
    std::string text;
    for (const auto& p : problems) text += (text.empty() ? "" : "\nrigger-compose: ") + p;
    fail(text + "\nrigger-compose: nothing started");
  }
  if (const auto holder = DomainLock::holder(file.domain, host_option(g))) {
    fail("a supervisor already runs for DDS domain " + std::to_string(file.domain) + " (pid " +
         std::to_string(holder->pid) + ", log dir " + holder->log_dir +
         "): `rigger-compose down` first, or `restart SERVICE`");
  }
  try {
    make_dirs(file.log_dir);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  const LogLayout layout(file.log_dir);
  std::printf("rigger-compose: starting %zu service%s on DDS domain %u (logs in %s)\n", local, local == 1 ? "" : "s",
              file.domain, file.log_dir.c_str());
  std::fflush(stdout);

  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) fail(std::string("pipe: ") + strerror(errno));
  // Keep the write end away from fd 3, where the supervisor expects it: dup2 onto itself would keep CLOEXEC.
  const int write_fd = fcntl(pipe_fds[1], F_DUPFD_CLOEXEC, 10);
  close(pipe_fds[1]);
  SpawnRequest req;
  req.path = self_executable();
  req.args = {"--file", file.path};
  if (g.domain) req.args.insert(req.args.end(), {"--domain", std::to_string(*g.domain)});
  if (!host_option(g).empty()) req.args.insert(req.args.end(), {"--host", host_option(g)});
  if (g.secure) req.args.push_back("--secure");
  req.args.insert(req.args.end(), {"supervise", "--notify-fd", "3"});
  req.args.insert(req.args.end(), services.begin(), services.end());
  req.log_path = layout.supervisor_log();
  req.cwd = file.root;
  req.new_session = true;  // a daemon: no controlling terminal, so the terminal's Ctrl-C never reaches it
  req.pass_fd = write_fd;
  int supervisor_pid = 0;
  try {
    supervisor_pid = spawn_process(req);
  } catch (const std::exception& e) {
    close(write_fd);
    close(pipe_fds[0]);
    fail("cannot start the supervisor: " + std::string(e.what()));
  }
  close(write_fd);

  // Progress until "OK" (everything READY) or end of file (the supervisor gave up and stopped everything).
  bool ok = false;
  std::string pending;
  char buf[1024];
  ssize_t n;
  while (!ok && ((n = read(pipe_fds[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR))) {
    if (n < 0) continue;
    pending.append(buf, static_cast<std::size_t>(n));
    std::size_t eol;
    while (!ok && (eol = pending.find('\n')) != std::string::npos) {
      const std::string line = pending.substr(0, eol);
      pending.erase(0, eol + 1);
      if (line == "OK")
        ok = true;
      else if (line.size() > 2 && line[0] == 'E') {
        std::fflush(stdout);
        std::fprintf(stderr, "rigger-compose: %s\n", line.c_str() + 2);
      } else if (line.size() > 2)
        std::printf("  %s\n", line.c_str() + 2);
      std::fflush(stdout);
    }
  }
  close(pipe_fds[0]);
  if (ok) {
    std::printf(
        "rigger-compose: %zu service%s READY in %.1f s (supervisor pid %d); `ps` shows them, `down` stops them\n",
        local, local == 1 ? "" : "s", seconds_since(started), supervisor_pid);
    std::fflush(stdout);
    return kExitOk;
  }
  int status = 0;
  while (waitpid(supervisor_pid, &status, 0) < 0 && errno == EINTR) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : kExitFailure;
  if (!WIFEXITED(status)) {
    std::fflush(stdout);
    std::fprintf(stderr, "rigger-compose: the supervisor was killed by SIG%s; stopping what it started\n",
                 sigabbrev_np(WTERMSIG(status)) ? sigabbrev_np(WTERMSIG(status)) : "?");
    stop_orphans(file, file.log_dir);
  }
  std::fflush(stdout);
  std::fprintf(stderr, "rigger-compose: up failed; nothing was left running (logs in %s)\n", file.log_dir.c_str());
  return code == kExitOk ? kExitFailure : code;
}

// -------------------------------------------------------------------------------------------- down

std::chrono::milliseconds total_stop_time(const ComposeFile& file) {
  std::chrono::milliseconds total{0};
  for (const auto& s : file.services) total += s.stop_timeout;
  return total + kSupervisorExitMargin;
}

int down(const GlobalOptions& g) {
  const ComposeFile file = load(g);
  const auto holder = DomainLock::holder(file.domain, host_option(g));
  if (!holder) {
    if (stop_orphans(file, file.log_dir) > 0) {
      std::printf("rigger-compose: stopped the services its dead supervisor had left running\n");
      return kExitOk;
    }
    std::printf("rigger-compose: no supervisor runs for DDS domain %u: nothing to stop\n", file.domain);
    return kExitOk;
  }
  const auto t0 = Clock::now();
  std::printf("rigger-compose: stopping the supervisor (pid %d, domain %u, logs in %s)\n", holder->pid, file.domain,
              holder->log_dir.c_str());
  std::fflush(stdout);
  if (!send_signal(holder->pid, SIGTERM) && process_alive(holder->pid))
    fail("cannot signal the supervisor pid " + std::to_string(holder->pid) + ": " + strerror(errno));
  if (!wait_for_exit(holder->pid, total_stop_time(file)))
    fail("the supervisor (pid " + std::to_string(holder->pid) + ") did not exit within " +
         std::to_string(total_stop_time(file).count() / 1000) + " s; see " +
         LogLayout(holder->log_dir).supervisor_log());
  if (const auto st = read_status_file(LogLayout(holder->log_dir).status_file())) {
    for (const auto& s : st->services) {
      if (!s.local) continue;
      std::printf("  %-24s %-8s %s\n", s.name.c_str(), s.state.c_str(), s.last_exit.c_str());
    }
  }
  std::printf("rigger-compose: stopped in %.1f s\n", seconds_since(t0));
  return kExitOk;
}

// ---------------------------------------------------------------------------------------------- ps

struct PsRow {
  std::string service;
  std::string host;
  int pid = 0;
  int restarts = -1;  // -1: not supervised here
  std::string state;  // from DDS: READY, STARTING, STOPPING, FAULT, LOST, or "-" (not seen)
  std::int64_t uptime_ms = -1;
  std::string supervisor;  // the supervisor's view, or "" when it does not run the service
  std::string note;
};

std::string dds_state(const dds::ServiceDirectory& dir, const std::string& id, int expected_pid) {
  auto it = dir.services().find(id);
  if (it == dir.services().end()) return "-";
  if (expected_pid > 0 && it->second.pid != expected_pid) return "-";  // an earlier instance's leftover
  if (!it->second.alive) return "LOST";
  return dds::to_string(it->second.status);
}

int ps(const GlobalOptions& g, bool json, double timeout_s) {
  const ComposeFile file = load(g);
  const auto holder = DomainLock::holder(file.domain, host_option(g));
  std::optional<SupervisorStatus> status;
  if (holder) status = read_status_file(LogLayout(holder->log_dir).status_file());

  use_dds_config(file);
  dds::Participant participant(file.domain);
  dds::EventLoop loop(participant);
  dds::ServiceDirectory dir(participant);
  loop.on_data(dir.reader(), [&dir] { dir.update(); });
  // Announcements are transient-local: they arrive right after discovery. Wait for those we expect
  // (the supervised processes), at most the timeout; with nothing to expect, give discovery the timeout.
  std::set<std::string> expected;
  if (status) {
    for (const auto& s : status->services)
      if (s.pid > 0) expected.insert(s.name);
  }
  const auto timeout = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(timeout_s));
  loop.run_until(
      [&] {
        if (expected.empty()) return false;
        for (const auto& id : expected)
          if (!dir.services().count(id)) return false;
        return true;
      },
      expected.empty() ? timeout / 2 : timeout);

  const auto now = unix_now_ms();
  std::vector<PsRow> rows;
  std::set<std::string> listed;
  for (const auto& def : file.services) {
    PsRow r;
    r.service = def.name;
    r.host = def.host;
    const ServiceStatusEntry* e = status ? status->find(def.name) : nullptr;
    if (e && e->local) {
      r.pid = e->pid;
      r.restarts = e->restarts;
      r.supervisor = e->state;
      if (e->pid > 0 && e->started_unix_ms > 0) r.uptime_ms = now - e->started_unix_ms;
      if (e->state == "backoff" && e->next_start_unix_ms > 0) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "restarts in %.1f s",
                      std::max<double>(0, (e->next_start_unix_ms - now) / 1000.0));
        r.note = buf;
      }
      if (r.note.empty() && e->pid == 0 && !e->last_exit.empty()) r.note = e->last_exit;
    } else if (auto it = dir.services().find(def.name); it != dir.services().end()) {
      r.pid = it->second.pid;
      if (!is_local_host(def.host, this_host_names(host_option(g)))) r.note = "pid on " + it->second.host;
    }
    r.state = dds_state(dir, def.name, e && e->local ? e->pid : 0);
    rows.push_back(r);
    listed.insert(def.name);
  }
  for (const auto& [id, info] : dir.services()) {
    if (listed.count(id)) continue;
    PsRow r;
    r.service = id;
    r.host = info.host;
    r.pid = info.pid;
    r.state = info.alive ? dds::to_string(info.status) : "LOST";
    r.note = "not in the compose file";
    rows.push_back(r);
  }

  if (json) {
    nlohmann::json out = nlohmann::json::object();
    out["domain"] = file.domain;
    out["supervisor_pid"] = holder ? holder->pid : 0;
    out["phase"] = status ? status->phase : "";
    out["services"] = nlohmann::json::array();
    for (const auto& r : rows) {
      out["services"].push_back({{"service", r.service},
                                 {"host", r.host},
                                 {"pid", r.pid},
                                 {"restarts", r.restarts},
                                 {"state", r.state},
                                 {"uptime_ms", r.uptime_ms},
                                 {"supervisor", r.supervisor},
                                 {"note", r.note}});
    }
    std::printf("%s\n", out.dump(2).c_str());
    return kExitOk;
  }
  if (holder) {
    std::printf("supervisor pid %d, domain %u, %s, logs in %s\n", holder->pid, file.domain,
                status ? status->phase.c_str() : "status unknown", holder->log_dir.c_str());
  } else {
    std::printf("no supervisor runs for domain %u on this host; DDS shows:\n", file.domain);
  }
  std::printf("%-22s %-14s %8s %8s  %-9s %8s  %-9s %s\n", "SERVICE", "HOST", "PID", "RESTARTS", "STATE", "UPTIME",
              "SUPERVISOR", "NOTE");
  for (const auto& r : rows) {
    std::printf("%-22s %-14s %8s %8s  %-9s %8s  %-9s %s\n", r.service.c_str(), r.host.c_str(),
                r.pid > 0 ? std::to_string(r.pid).c_str() : "-",
                r.restarts >= 0 ? std::to_string(r.restarts).c_str() : "-", r.state.c_str(),
                format_uptime(r.uptime_ms).c_str(), r.supervisor.empty() ? "-" : r.supervisor.c_str(), r.note.c_str());
  }
  return kExitOk;
}

// -------------------------------------------------------------------------------------------- logs

volatile sig_atomic_t g_follow_stop = 0;

int logs(const GlobalOptions& g, const std::string& service, bool follow, int last_lines) {
  const ComposeFile file = load(g);
  if (service != "supervisor" && !file.find(service))
    fail("no service named '" + service + "' in " + file.path + " (or use 'supervisor')", kExitUsage);
  const LogLayout layout(file.log_dir);
  const std::string path = service == "supervisor" ? layout.supervisor_log() : layout.service_log(service);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("no log for " + service + " yet (" + path + ")");

  if (last_lines > 0) {
    std::deque<std::string> tail;
    std::string line;
    while (std::getline(in, line)) {
      tail.push_back(line);
      if (static_cast<int>(tail.size()) > last_lines) tail.pop_front();
    }
    for (const auto& l : tail) std::printf("%s\n", l.c_str());
    in.clear();
  } else {
    std::cout << in.rdbuf();
    in.clear();
  }
  std::fflush(stdout);
  std::cout.flush();
  if (!follow) return kExitOk;

  // Follow with inotify: wake on every write, never poll on a timer.
  const int ino = inotify_init1(IN_CLOEXEC);
  if (ino < 0 || inotify_add_watch(ino, path.c_str(), IN_MODIFY | IN_DELETE_SELF | IN_MOVE_SELF) < 0)
    fail("cannot follow " + path + ": " + strerror(errno));
  struct sigaction sa {};
  sa.sa_handler = [](int) { g_follow_stop = 1; };
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  in.seekg(0, std::ios::end);
  auto pos = in.tellg();
  char events[4096];
  while (!g_follow_stop) {
    const ssize_t n = read(ino, events, sizeof events);
    if (n <= 0) {
      if (errno == EINTR) continue;
      break;
    }
    std::ifstream again(path, std::ios::binary);
    again.seekg(0, std::ios::end);
    const auto size = again.tellg();
    if (size < pos) pos = 0;  // truncated or replaced
    again.seekg(pos);
    std::cout << again.rdbuf();
    std::cout.flush();
    pos = size;
  }
  close(ino);
  return kExitOk;
}

// ----------------------------------------------------------------------------------------- restart

int restart(const GlobalOptions& g, const std::string& service) {
  const ComposeFile file = load(g);
  const ServiceDef* def = file.find(service);
  if (!def) fail("no service named '" + service + "' in " + file.path, kExitUsage);
  if (!is_local_host(def->host, this_host_names(host_option(g))))
    fail("service " + service + " runs on host " + def->host + ": run `rigger-compose restart " + service + "` there");
  const auto holder = DomainLock::holder(file.domain, host_option(g));
  if (!holder) fail("no supervisor runs for DDS domain " + std::to_string(file.domain) + ": `rigger-compose up` first");
  const LogLayout layout(holder->log_dir);
  const auto status = read_status_file(layout.status_file());
  if (!status) fail("cannot read the supervisor's status (" + layout.status_file() + ")");
  const ServiceStatusEntry* entry = status->find(service);
  if (!entry || !entry->local) fail("the supervisor (pid " + std::to_string(holder->pid) + ") does not run " + service);
  if (status->phase != "running")
    fail("the supervisor is " + status->phase + "; restart is possible once every service is READY");
  const int old_pid = entry->pid;

  use_dds_config(file);
  dds::Participant participant(file.domain);
  dds::EventLoop loop(participant);
  dds::ServiceDirectory dir(participant);
  loop.on_data(dir.reader(), [&dir] { dir.update(); });

  const int fd = open(layout.control_fifo().c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail("cannot reach the supervisor through " + layout.control_fifo() + ": " + strerror(errno));
  const std::string request = "restart " + service + "\n";
  const bool sent = write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size());
  close(fd);
  if (!sent) fail("cannot send the request to the supervisor: " + std::string(strerror(errno)));
  const auto t0 = Clock::now();
  std::printf("rigger-compose: restarting %s (pid %s)\n", service.c_str(),
              old_pid > 0 ? std::to_string(old_pid).c_str() : "none");
  std::fflush(stdout);

  const auto timeout = def->stop_timeout + def->ready_timeout + std::chrono::seconds(5);
  int new_pid = 0;
  const bool ok = loop.run_until(
      [&] {
        auto it = dir.services().find(service);
        if (it == dir.services().end() || !it->second.alive || it->second.status != dds::ServiceStatus::kReady)
          return false;
        if (it->second.pid == old_pid || it->second.pid <= 0) return false;
        new_pid = it->second.pid;
        return true;
      },
      timeout);
  if (!ok) {
    fail("service " + service + " was not READY again within " + std::to_string(timeout.count() / 1000) +
         " s; see `rigger-compose logs " + service + "` and " + layout.supervisor_log());
  }
  std::printf("rigger-compose: %s READY again, pid %d, after %.1f s\n", service.c_str(), new_pid, seconds_since(t0));
  return kExitOk;
}

// -------------------------------------------------------------------------------------------- demo

/// Writes fresh users for the compose file's console (its configuration's users_file) with `console
/// make-users` and prints their login links; nothing when the file has no console or it is not built.
void console_logins(const ComposeFile& file) {
  const ServiceDef* console = file.find("console");
  if (!console || access(console->binary.c_str(), X_OK) != 0) return;
  std::string address = "127.0.0.1", users = "/var/tmp/rigger/console-users.json";
  int port = 8080;
  if (!console->config.empty()) {
    const auto parsed = parse_json_file_bounded(console->config);
    const auto& c = parsed.value;
    if (parsed.ok() && c.is_object()) {
      address = c.value("address", address);
      port = c.value("port", port);
      users = c.value("users_file", users);
    }
  }
  const std::string url = "http://" + address + ":" + std::to_string(port);
  std::printf("rigger-compose demo: the console at %s/ — log in with one of these links (new tokens each demo):\n",
              url.c_str());
  std::fflush(stdout);
  SpawnRequest req;
  req.path = console->binary;
  req.args = {"make-users", "--file", users, "--user", "operator:operator", "--user", "programmer:programmer",
              "--user", "viewer:viewer", "--url", url};
  try {
    const int pid = spawn_process(req);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigger-compose demo: cannot run console make-users: %s\n", e.what());
  }
}

int demo(const GlobalOptions& g, const std::string& recipe_arg, const std::string& operator_mode) {
  const ComposeFile file = load(g);
  if (operator_mode != "scripted" && operator_mode != "browser")
    fail("--operator " + operator_mode + ": expected scripted or browser", kExitUsage);
  console_logins(file);
  // --operator browser: everything but the scripted operator, so a person answers at the console.
  std::vector<std::string> services;
  if (operator_mode == "browser") {
    for (const auto& s : file.services)
      if (s.name != "scripted_operator") services.push_back(s.name);
    std::printf("rigger-compose demo: no scripted operator: answer the screw prompts at the console's Operator station\n");
  }
  const int up_code = up(g, services);
  if (up_code != kExitOk) return up_code;

  const std::string riggerctl = file.bin_dir + "/riggerctl";
  const std::string recipe =
      !recipe_arg.empty() && recipe_arg.front() == '/' ? recipe_arg : file.root + "/" + recipe_arg;
  std::string missing;
  if (access(riggerctl.c_str(), X_OK) != 0)
    missing = file.display_path(riggerctl) + " not found — not built yet?";
  else if (access(recipe.c_str(), R_OK) != 0)
    missing = "recipe " + file.display_path(recipe) + " not found — not written yet?";
  int code = kExitOk;
  if (!missing.empty()) {
    std::fflush(stdout);
    std::fprintf(stderr, "rigger-compose demo: %s; stopping the cell\n", missing.c_str());
    code = kExitFailure;
  } else {
    std::printf("rigger-compose demo: %s run %s\n", file.display_path(riggerctl).c_str(),
                file.display_path(recipe).c_str());
    std::fflush(stdout);
    SpawnRequest req;
    req.path = riggerctl;
    // A task id is used once (the journal keeps every task): each demo run submits under a new one.
    char stamp[32];
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    localtime_r(&now, &tm);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
    const std::string task_id = std::filesystem::path(recipe).stem().string() + "-" + stamp;
    req.args = {"--domain", std::to_string(file.domain), "run", recipe, "--task-id", task_id};
    req.env["RIGGER_DOMAIN"] = std::to_string(file.domain);
    if (!file.dds_config.empty()) req.env["CYCLONEDDS_URI"] = file.dds_uri();
    if (g.secure) req.env["RIGGER_IDENTITY"] = kRiggerctlIdentity;
    // Ctrl-C goes to riggerctl (same terminal process group), which cancels the task; we then still
    // bring the cell down.
    struct sigaction ignore {
    }, old_int{}, old_term{};
    ignore.sa_handler = SIG_IGN;
    sigaction(SIGINT, &ignore, &old_int);
    sigaction(SIGTERM, &ignore, &old_term);
    const auto t0 = Clock::now();
    try {
      const int pid = spawn_process(req);
      int status = 0;
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      std::printf("rigger-compose demo: riggerctl %s after %.1f s\n",
                  clean ? "succeeded"
                        : (WIFEXITED(status) ? ("failed with exit code " + std::to_string(WEXITSTATUS(status))).c_str()
                                             : "was killed"),
                  seconds_since(t0));
      code = clean ? kExitOk : kExitFailure;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rigger-compose demo: cannot run riggerctl: %s\n", e.what());
      code = kExitFailure;
    }
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
  int down_code = kExitFailure;
  try {
    down_code = down(g);
  } catch (const CommandError& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.message.c_str());
  }
  return code != kExitOk ? code : down_code;
}

// ------------------------------------------------------------------------------------------ config

int config(const GlobalOptions& g) {
  const ComposeFile file = load(g);
  const auto hosts = this_host_names(host_option(g));
  std::vector<ServiceDeps> graph;
  for (const auto& s : file.services) graph.push_back({s.name, s.depends_on});
  std::printf("file     %s\nroot     %s\ndomain   %u\ndds      %s\nlog_dir  %s\nbin_dir  %s\n", file.path.c_str(),
              file.root.c_str(), file.domain, file.dds_config.empty() ? "(CYCLONEDDS_URI)" : file.dds_config.c_str(),
              file.log_dir.c_str(), file.bin_dir.c_str());
  std::printf("services in start order:\n");
  bool any_remote = false;
  for (const auto& name : start_order(graph)) {
    const auto& s = *file.find(name);
    const bool built = access(s.binary.c_str(), X_OK) == 0;
    any_remote = any_remote || !is_local_host(s.host, hosts);
    std::string deps;
    for (const auto& d : s.depends_on) deps += (deps.empty() ? "" : ",") + d;
    std::printf("  %-20s host=%-12s restart=%-10s %s%s%s%s\n", name.c_str(),
                (s.host + (is_local_host(s.host, hosts) ? "" : "*")).c_str(), to_string(s.restart),
                file.display_path(s.binary).c_str(), built ? "" : " (not built)",
                s.config.empty() ? "" : (" --config " + file.display_path(s.config)).c_str(),
                deps.empty() ? "" : ("  after " + deps).c_str());
  }
  if (any_remote) std::printf("(* another host: started there, from the same file)\n");
  return kExitOk;
}

// --------------------------------------------------------------------------------------- supervise

int supervise(const GlobalOptions& g, const std::vector<std::string>& services, int notify_fd) {
  if (notify_fd >= 0) fcntl(notify_fd, F_SETFD, FD_CLOEXEC);
  Logger log;
  try {
    log = make_logger("rigger-compose");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.what());
    return kExitUsage;
  }
  ComposeFile file;
  try {
    file = load(g);
  } catch (const ComposeError& e) {
    log->critical("bad compose file: {}", e.what());
    if (notify_fd >= 0) {
      const std::string line = std::string("E ") + e.what() + "\n";
      (void)!write(notify_fd, line.data(), line.size());
    }
    return kExitUsage;
  }
  SupervisorOptions options;
  options.services = services;
  options.this_host_names = this_host_names(host_option(g));
  options.host = host_option(g);
  options.notify_fd = notify_fd;
  return run_supervisor(file, options, log);
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App app{"rigger-compose: runs the services of a compose file (deploy/compose.yaml) as supervised processes",
               "rigger-compose"};
  app.require_subcommand(1);
  app.fallthrough();
  GlobalOptions g;
  app.add_option("-f,--file", g.file,
                 "Compose file (default: deploy/compose.yaml of the installation, <prefix>/share/rigger)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--domain", g.domain, "DDS domain id, overriding dds.domain")->check(CLI::Range(0, 232));
  app.add_option("--host", g.host, "This host's name for `host:` placement (default $RIGGER_HOST, the host name)");
  app.add_flag("--secure", g.secure,
               "DDS Security: the services, rigger-compose and demo's riggerctl join with their identities from "
               "$RIGGER_SECURITY_DIR (default /var/tmp/rigger/security; deploy/security/make-pki makes it) "
               "over deploy/cyclonedds-secure.xml (docs/security.md)");

  int code = kExitOk;
  std::function<int()> action;
  auto* up_cmd = app.add_subcommand("up", "Start the services (and their dependencies); return when all are READY");
  auto up_services = std::make_shared<std::vector<std::string>>();
  up_cmd->add_option("services", *up_services, "Services to start (default: every service of this host)");
  up_cmd->callback([&] { action = [&] { return up(g, *up_services); }; });

  app.add_subcommand("down", "Stop every service in reverse dependency order and the supervisor")->callback([&] {
    action = [&] { return down(g); };
  });

  auto* ps_cmd = app.add_subcommand("ps", "Show the services: supervisor state merged with their DDS state");
  auto ps_json = std::make_shared<bool>(false);
  auto ps_timeout = std::make_shared<double>(2.0);
  ps_cmd->add_flag("--json", *ps_json, "Print JSON");
  ps_cmd->add_option("--timeout", *ps_timeout, "Seconds to wait for DDS discovery (default 2)")
      ->check(CLI::Range(0.1, 60.0));
  ps_cmd->callback([&] { action = [&] { return ps(g, *ps_json, *ps_timeout); }; });

  auto* logs_cmd = app.add_subcommand("logs", "Print a service's log ('supervisor' for the supervisor's)");
  auto logs_service = std::make_shared<std::string>();
  auto logs_follow = std::make_shared<bool>(false);
  auto logs_lines = std::make_shared<int>(0);
  logs_cmd->add_option("service", *logs_service, "Service name")->required();
  logs_cmd->add_flag("-f,--follow", *logs_follow, "Keep printing what is appended (Ctrl-C ends)");
  logs_cmd->add_option("-n,--lines", *logs_lines, "Only the last N lines")->check(CLI::Range(1, 1000000));
  logs_cmd->callback([&] { action = [&] { return logs(g, *logs_service, *logs_follow, *logs_lines); }; });

  auto* restart_cmd = app.add_subcommand("restart", "Restart one service and wait until it is READY again");
  auto restart_service = std::make_shared<std::string>();
  restart_cmd->add_option("service", *restart_service, "Service name")->required();
  restart_cmd->callback([&] { action = [&] { return restart(g, *restart_service); }; });

  auto* demo_cmd = app.add_subcommand("demo", "up, run the scenario recipe with riggerctl while streaming it, down");
  auto demo_recipe = std::make_shared<std::string>("recipes/crane_insert.json");
  demo_cmd->add_option("--recipe", *demo_recipe,
                       "Recipe, relative to the repository root (default recipes/crane_insert.json)");
  auto demo_operator = std::make_shared<std::string>("scripted");
  demo_cmd->add_option("--operator", *demo_operator,
                       "Who answers the operator prompts: scripted (default) or browser (a person at the console)");
  demo_cmd->callback([&] { action = [&] { return demo(g, *demo_recipe, *demo_operator); }; });

  app.add_subcommand("config", "Validate the compose file and show it resolved, in start order")->callback([&] {
    action = [&] { return config(g); };
  });

  auto* sup_cmd = app.add_subcommand("supervise", "");  // internal: the daemon `up` starts
  sup_cmd->group("");
  auto sup_services = std::make_shared<std::vector<std::string>>();
  auto sup_fd = std::make_shared<int>(-1);
  sup_cmd->add_option("services", *sup_services);
  sup_cmd->add_option("--notify-fd", *sup_fd);
  sup_cmd->callback([&] { action = [&] { return supervise(g, *sup_services, *sup_fd); }; });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    code = action ? action() : kExitUsage;
  } catch (const CommandError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "rigger-compose: %s\n", e.message.c_str());
    code = e.code;
  } catch (const ComposeError& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.what());
    code = kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.what());
    code = kExitFailure;
  }
  return code;
}

}  // namespace rigger::compose
