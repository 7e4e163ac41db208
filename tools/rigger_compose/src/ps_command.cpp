// rigger-compose ps: the supervisor's status file merged with what DDS shows of each service.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/status_file.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::compose::cli {
namespace {

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

std::string dds_state(const service::ServiceDirectory& dir, const std::string& id, int expected_pid) {
  auto it = dir.services().find(id);
  if (it == dir.services().end()) return "-";
  if (expected_pid > 0 && it->second.pid != expected_pid) return "-";  // an earlier instance's leftover
  if (!it->second.alive) return "LOST";
  return service::to_string(it->second.status);
}

}  // namespace

int ps(const GlobalOptions& g, bool json, double timeout_s) {
  const ComposeFile file = load(g);
  const auto holder = DomainLock::holder(file.domain, host_option(g));
  std::optional<SupervisorStatus> status;
  if (holder) status = read_status_file(LogLayout(holder->log_dir).status_file());

  use_dds_config(file);
  dds::Participant participant(file.domain);
  dds::EventLoop loop(participant);
  service::ServiceDirectory dir(participant);
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
    r.state = info.alive ? service::to_string(info.status) : "LOST";
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

}  // namespace rigger::compose::cli
