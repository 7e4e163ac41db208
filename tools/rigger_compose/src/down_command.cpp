// rigger-compose down: signals the supervisor, waits for it to stop every service, prints how each ended.
#include <errno.h>
#include <signal.h>
#include <string.h>

#include <chrono>
#include <cstdio>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/status_file.hpp"

namespace rigger::compose::cli {
namespace {

constexpr auto kSupervisorExitMargin = std::chrono::seconds(10);

std::chrono::milliseconds total_stop_time(const ComposeFile& file) {
  std::chrono::milliseconds total{0};
  for (const auto& s : file.services) total += s.stop_timeout;
  return total + kSupervisorExitMargin;
}

}  // namespace

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

}  // namespace rigger::compose::cli
