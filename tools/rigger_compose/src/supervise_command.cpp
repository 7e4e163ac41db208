// rigger-compose supervise: the daemon `up` starts, or a foreground supervisor its caller owns (the
// console's rehearsal cell, with --in-group): runs the supervisor, telling `up`
// its progress on the notify fd.
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>

#include "command_support.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/supervisor.hpp"

namespace rigger::compose::cli {

int supervise(const GlobalOptions& g, const std::vector<std::string>& services, int notify_fd, bool in_group) {
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
  options.services_in_group = in_group;
  return run_supervisor(file, options, log);
}

}  // namespace rigger::compose::cli
