// rigger-compose up: checks everything first, starts the supervisor as a daemon and reports its
// progress until every service is READY or it gave up.
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <set>
#include <stdexcept>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/supervision.hpp"

namespace rigger::compose::cli {
namespace {

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

}  // namespace

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

}  // namespace rigger::compose::cli
