// rigger-compose restart: asks the supervisor through its control FIFO and waits on DDS for the
// service's new instance to be READY.
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/status_file.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::compose::cli {

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
  service::ServiceDirectory dir(participant);
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
        if (it == dir.services().end() || !it->second.alive || it->second.status != service::ServiceStatus::kReady)
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

}  // namespace rigger::compose::cli
