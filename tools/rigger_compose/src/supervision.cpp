#include "rigger/compose/supervision.hpp"

#include <signal.h>
#include <string.h>

#include <algorithm>
#include <cstdio>

#include "rigger/compose/start_order.hpp"

namespace rigger::compose {
namespace {

using Level = SupervisionCommand::Level;

std::string seconds(Clock::duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", std::chrono::duration<double>(d).count());
  return buf;
}

bool is_running(ServiceState s) {
  return s == ServiceState::kStarting || s == ServiceState::kReady || s == ServiceState::kStopping;
}

bool restart_wanted(RestartPolicy policy, bool failed) {
  switch (policy) {
    case RestartPolicy::kAlways: return true;
    case RestartPolicy::kOnFailure: return failed;
    case RestartPolicy::kNo: return false;
  }
  return false;
}

}  // namespace

std::string ExitInfo::describe() const {
  if (exited) return "exit code " + std::to_string(code);
  const char* abbrev = sigabbrev_np(signal);
  return abbrev ? std::string("killed by SIG") + abbrev : "killed by signal " + std::to_string(signal);
}

const char* to_string(ServiceState state) {
  switch (state) {
    case ServiceState::kWaiting: return "waiting";
    case ServiceState::kStarting: return "starting";
    case ServiceState::kReady: return "ready";
    case ServiceState::kBackoff: return "backoff";
    case ServiceState::kStopping: return "stopping";
    case ServiceState::kStopped: return "stopped";
    case ServiceState::kExited: return "exited";
    case ServiceState::kFailed: return "failed";
    case ServiceState::kRemote: return "remote";
  }
  return "?";
}

const char* to_string(Phase phase) {
  switch (phase) {
    case Phase::kStarting: return "starting";
    case Phase::kRunning: return "running";
    case Phase::kStopping: return "stopping";
    case Phase::kDone: return "done";
  }
  return "?";
}

Supervision::Supervision(const std::vector<Entry>& plan) {
  services_.reserve(plan.size());
  for (const auto& e : plan) {
    ServiceRuntime s;
    s.def = e.def;
    s.local = e.local;
    s.state = e.local ? ServiceState::kWaiting : ServiceState::kRemote;
    services_.push_back(s);
  }
  extras_.resize(services_.size());
}

const ServiceRuntime* Supervision::find(const std::string& service) const {
  for (const auto& s : services_)
    if (s.name() == service) return &s;
  return nullptr;
}

ServiceRuntime* Supervision::find_mutable(const std::string& service) {
  return const_cast<ServiceRuntime*>(static_cast<const Supervision*>(this)->find(service));
}

void Supervision::report(Level level, std::string text) {
  SupervisionCommand c;
  c.kind = SupervisionCommand::Kind::kReport;
  c.level = level;
  c.text = std::move(text);
  commands_.push_back(std::move(c));
}

std::string Supervision::elapsed(Clock::time_point now) const {
  char buf[32];
  std::snprintf(buf, sizeof buf, "[%6.2f s]", std::chrono::duration<double>(now - began_).count());
  return buf;
}

void Supervision::begin(Clock::time_point now) {
  if (begun_) return;
  begun_ = true;
  began_ = now;
  for (auto& s : services_) {
    // A remote dependency gets its own ready timeout, counted from the start of the bring-up.
    if (!s.local) s.deadline = now + s.def->ready_timeout;
  }
  pump(now);
}

void Supervision::spawn(ServiceRuntime& s, Clock::time_point now, bool is_restart) {
  if (is_restart) ++s.restarts;
  s.state = ServiceState::kStarting;
  s.pid = 0;
  s.started = now;
  s.ready_at.reset();
  s.deadline = now + s.def->ready_timeout;
  extra(s).after_stop = AfterStop::kNothing;
  extra(s).sigkill_sent = false;
  SupervisionCommand c;
  c.kind = SupervisionCommand::Kind::kSpawn;
  c.service = s.name();
  commands_.push_back(std::move(c));
}

void Supervision::spawned(const std::string& service, int pid, Clock::time_point now) {
  auto* s = find_mutable(service);
  if (!s || s->state != ServiceState::kStarting) return;
  s->pid = pid;
  report(Level::kDetail, elapsed(now) + " " + service + " started, pid " + std::to_string(pid) +
                             (s->restarts ? " (restart #" + std::to_string(s->restarts) + ")" : ""));
  pump(now);
}

void Supervision::spawn_failed(const std::string& service, const std::string& error, Clock::time_point now) {
  auto* s = find_mutable(service);
  if (!s || s->state != ServiceState::kStarting) return;
  s->pid = 0;
  s->last_exit = "could not start: " + error;
  if (phase_ == Phase::kStarting) {
    s->state = ServiceState::kFailed;
    s->deadline.reset();
    fail_bring_up("service " + service + ": " + s->last_exit, now);
    return;
  }
  // After the bring-up (e.g. the binary is being rebuilt): retry with backoff like a crash.
  ended_on_its_own(*s, /*failed=*/true, now);
  pump(now);
}

void Supervision::exited(int pid, const ExitInfo& info, Clock::time_point now) {
  if (pid <= 0) return;
  auto it = std::find_if(services_.begin(), services_.end(), [pid](const ServiceRuntime& s) { return s.pid == pid; });
  if (it == services_.end()) return;
  ServiceRuntime& s = *it;
  s.pid = 0;
  s.last_exit = info.describe();
  const auto ran = seconds(now - s.started);

  if (s.state == ServiceState::kStopping) {
    const AfterStop after = extra(s).after_stop;
    const bool clean = info.success() && !extra(s).sigkill_sent;
    if (after == AfterStop::kRestartNow && (phase_ == Phase::kRunning || phase_ == Phase::kStarting)) {
      report(Level::kInfo, elapsed(now) + " " + s.name() + " stopped (" + s.last_exit + "); starting it again");
      spawn(s, now, true);
    } else if (after == AfterStop::kRestartPerPolicy && phase_ == Phase::kRunning) {
      ended_on_its_own(s, /*failed=*/true, now);  // it was stopped because it never became READY
    } else {
      s.state = ServiceState::kStopped;
      s.deadline.reset();
      report(clean ? Level::kInfo : Level::kWarn, elapsed(now) + " " + s.name() + " stopped (" + s.last_exit + ")");
    }
    pump(now);
    return;
  }

  if (phase_ == Phase::kStopping || phase_ == Phase::kDone) {
    s.state = ServiceState::kStopped;
    s.deadline.reset();
    report(Level::kWarn, elapsed(now) + " " + s.name() + " ended by itself while stopping (" + s.last_exit + ")");
    pump(now);
    return;
  }

  if (phase_ == Phase::kStarting && !s.ready_at) {
    s.state = ServiceState::kFailed;
    s.deadline.reset();
    fail_bring_up(
        "service " + s.name() + " ended (" + s.last_exit + ") after " + ran + " before it announced READY; see its log",
        now);
    return;
  }
  ended_on_its_own(s, !info.success(), now);
  pump(now);
}

void Supervision::ended_on_its_own(ServiceRuntime& s, bool failed, Clock::time_point now) {
  const auto ran_for = std::chrono::duration_cast<std::chrono::milliseconds>(now - s.started);
  if (restart_wanted(s.def->restart, failed)) {
    const auto delay = extra(s).backoff.next_delay(ran_for);
    s.state = ServiceState::kBackoff;
    s.deadline = now + delay;
    report(Level::kWarn, elapsed(now) + " " + s.name() + " ended (" + s.last_exit + ") after " +
                             seconds(now - s.started) + "; restart #" + std::to_string(s.restarts + 1) + " in " +
                             seconds(delay));
    return;
  }
  s.state = ServiceState::kExited;
  s.deadline.reset();
  const std::string text =
      s.name() + " ended (" + s.last_exit + "); restart policy '" + to_string(s.def->restart) + "': not restarted";
  // During the bring-up the cell can then never be complete: say so now rather than wait forever.
  if (phase_ == Phase::kStarting) {
    fail_bring_up("service " + text, now);
    return;
  }
  report(failed ? Level::kWarn : Level::kInfo, elapsed(now) + " " + text);
}

void Supervision::announced_ready(const std::string& service, int pid, Clock::time_point now) {
  auto* s = find_mutable(service);
  if (!s) return;
  if (!s->local) {
    if (!s->remote_ready) {
      s->remote_ready = true;
      s->deadline.reset();
      report(Level::kInfo, elapsed(now) + " " + service + " READY on host " + s->def->host);
      pump(now);
    }
    return;
  }
  // Only the instance we spawned counts: a READY left over from the previous instance must not.
  if (s->state != ServiceState::kStarting || s->pid == 0 || s->pid != pid) return;
  s->state = ServiceState::kReady;
  s->ready_at = now;
  s->deadline.reset();
  report(Level::kInfo, elapsed(now) + " " + service + " READY (pid " + std::to_string(pid) + ", " +
                           seconds(now - s->started) + " after start)");
  pump(now);
}

void Supervision::announced_lost(const std::string& service, Clock::time_point now) {
  auto* s = find_mutable(service);
  if (!s || s->local || !s->remote_ready) return;
  s->remote_ready = false;
  report(Level::kWarn, elapsed(now) + " " + service + " on host " + s->def->host + " is no longer READY");
}

void Supervision::signal_stop(ServiceRuntime& s, AfterStop after, Clock::time_point now) {
  extra(s).after_stop = after;
  if (s.state == ServiceState::kStopping) return;  // already signalled; keep its SIGKILL deadline
  s.state = ServiceState::kStopping;
  s.deadline = now + s.def->stop_timeout;
  extra(s).sigkill_sent = false;
  SupervisionCommand c;
  c.kind = SupervisionCommand::Kind::kSignal;
  c.service = s.name();
  c.pid = s.pid;
  c.signal = SIGINT;
  commands_.push_back(std::move(c));
  report(Level::kDetail, elapsed(now) + " " + s.name() + ": SIGINT to pid " + std::to_string(s.pid));
}

void Supervision::stop(const std::string& reason, Clock::time_point now) {
  if (phase_ == Phase::kStopping || phase_ == Phase::kDone) return;
  phase_ = Phase::kStopping;
  report(failure_.empty() ? Level::kInfo : Level::kWarn, elapsed(now) + " stopping: " + reason);
  for (auto& s : services_) {
    if (!s.local) {
      s.deadline.reset();
      continue;
    }
    if (s.state == ServiceState::kWaiting || s.state == ServiceState::kBackoff) {
      s.state = ServiceState::kStopped;
      s.deadline.reset();
    }
    if (s.state == ServiceState::kStopping) extra(s).after_stop = AfterStop::kNothing;
  }
  pump(now);
}

std::string Supervision::restart(const std::string& service, Clock::time_point now) {
  auto* s = find_mutable(service);
  if (!s) return "service " + service + " is not run by this supervisor";
  if (!s->local) return "service " + service + " runs on host " + s->def->host + ", not here";
  if (phase_ != Phase::kRunning)
    return std::string("the supervisor is ") + to_string(phase_) + "; restart is possible once every service is READY";
  extra(*s).backoff.reset();
  switch (s->state) {
    case ServiceState::kStarting:
    case ServiceState::kReady:
      report(Level::kInfo, elapsed(now) + " restarting " + service + " on request");
      signal_stop(*s, AfterStop::kRestartNow, now);
      break;
    case ServiceState::kStopping: extra(*s).after_stop = AfterStop::kRestartNow; break;
    case ServiceState::kBackoff:
    case ServiceState::kExited:
    case ServiceState::kFailed:
    case ServiceState::kStopped:
    case ServiceState::kWaiting:
      report(Level::kInfo, elapsed(now) + " starting " + service + " on request");
      spawn(*s, now, true);
      break;
    case ServiceState::kRemote: break;
  }
  return "";
}

void Supervision::fail_bring_up(const std::string& reason, Clock::time_point now) {
  if (failure_.empty()) failure_ = reason;
  report(Level::kError, reason);
  stop("the bring-up failed", now);
}

void Supervision::advance(Clock::time_point now) {
  for (auto& s : services_) {
    if (!s.deadline || *s.deadline > now) continue;
    switch (s.state) {
      case ServiceState::kStarting:
        if (phase_ == Phase::kStarting) {
          s.deadline.reset();
          fail_bring_up("service " + s.name() + " did not announce READY within " + seconds(s.def->ready_timeout) +
                            " (pid " + std::to_string(s.pid) + "); see its log",
                        now);
        } else {
          report(Level::kError, elapsed(now) + " " + s.name() + " did not announce READY within " +
                                    seconds(s.def->ready_timeout) + " after its restart; stopping it");
          s.last_exit = "not READY within " + seconds(s.def->ready_timeout);
          signal_stop(s, AfterStop::kRestartPerPolicy, now);
        }
        break;
      case ServiceState::kBackoff:
        s.deadline.reset();
        report(Level::kInfo,
               elapsed(now) + " restarting " + s.name() + " (restart #" + std::to_string(s.restarts + 1) + ")");
        spawn(s, now, true);
        break;
      case ServiceState::kStopping:
        s.deadline.reset();
        if (!extra(s).sigkill_sent && s.pid > 0) {
          extra(s).sigkill_sent = true;
          SupervisionCommand c;
          c.kind = SupervisionCommand::Kind::kSignal;
          c.service = s.name();
          c.pid = s.pid;
          c.signal = SIGKILL;
          commands_.push_back(std::move(c));
          report(Level::kWarn, elapsed(now) + " " + s.name() + " did not stop within " + seconds(s.def->stop_timeout) +
                                   " after SIGINT; SIGKILL to pid " + std::to_string(s.pid));
        }
        break;
      case ServiceState::kRemote:
        s.deadline.reset();
        if (phase_ == Phase::kStarting && !s.remote_ready) {
          fail_bring_up("service " + s.name() + " (host " + s.def->host + ") is not READY after " +
                            seconds(s.def->ready_timeout) + ": start it on " + s.def->host +
                            " with `rigger-compose --host " + s.def->host + " up " + s.name() +
                            "` and the same compose file",
                        now);
        }
        break;
      default: s.deadline.reset(); break;
    }
  }
  pump(now);
}

bool Supervision::dependencies_ready(const ServiceRuntime& s) const {
  for (const auto& dep : s.def->depends_on) {
    const auto* d = find(dep);
    if (!d) continue;  // not part of this plan (cannot happen with a plan built by with_dependencies)
    if (d->local ? d->state != ServiceState::kReady : !d->remote_ready) return false;
  }
  return true;
}

bool Supervision::has_running_dependant(const ServiceRuntime& s) const {
  for (const auto& other : services_) {
    if (!other.local || !is_running(other.state)) continue;
    const auto& deps = other.def->depends_on;
    if (std::find(deps.begin(), deps.end(), s.name()) != deps.end()) return true;
  }
  return false;
}

void Supervision::pump(Clock::time_point now) {
  if (!begun_) return;
  if (phase_ == Phase::kStarting || phase_ == Phase::kRunning) {
    for (auto& s : services_) {
      if (s.local && s.state == ServiceState::kWaiting && dependencies_ready(s)) spawn(s, now, false);
    }
  }
  if (phase_ == Phase::kStarting) {
    const bool all_ready = std::all_of(services_.begin(), services_.end(), [](const ServiceRuntime& s) {
      return !s.local || s.state == ServiceState::kReady;
    });
    if (all_ready) {
      phase_ = Phase::kRunning;
      std::size_t local = 0;
      for (const auto& s : services_) local += s.local ? 1 : 0;
      report(Level::kInfo,
             elapsed(now) + " all " + std::to_string(local) + (local == 1 ? " service" : " services") + " READY");
    }
  }
  if (phase_ == Phase::kStopping) {
    // Reverse dependency order: a service is asked to stop once nothing that depends on it runs.
    for (auto& s : services_) {
      if (!s.local || (s.state != ServiceState::kStarting && s.state != ServiceState::kReady)) continue;
      if (has_running_dependant(s)) continue;
      if (s.pid == 0) {  // its spawn never completed: nothing to signal
        s.state = ServiceState::kStopped;
        s.deadline.reset();
        continue;
      }
      signal_stop(s, AfterStop::kNothing, now);
    }
    const bool any_running = std::any_of(services_.begin(), services_.end(),
                                         [](const ServiceRuntime& s) { return s.local && is_running(s.state); });
    if (!any_running) {
      phase_ = Phase::kDone;
      report(failure_.empty() ? Level::kInfo : Level::kWarn,
             elapsed(now) +
                 (failure_.empty() ? " every service stopped" : " every service stopped after the failed bring-up"));
    }
  }
}

std::vector<SupervisionCommand> Supervision::take_commands() {
  std::vector<SupervisionCommand> out;
  out.swap(commands_);
  return out;
}

std::optional<Clock::time_point> Supervision::next_deadline() const {
  std::optional<Clock::time_point> out;
  for (const auto& s : services_) {
    if (s.deadline && (!out || *s.deadline < *out)) out = s.deadline;
  }
  return out;
}

std::vector<Supervision::Entry> make_plan(const ComposeFile& file, const std::vector<std::string>& selected,
                                          const std::vector<std::string>& this_host_names) {
  std::vector<ServiceDeps> graph;
  for (const auto& s : file.services) graph.push_back({s.name, s.depends_on});
  for (const auto& name : selected) {
    const auto* def = file.find(name);
    if (!def) throw std::invalid_argument("no service named '" + name + "' in " + file.path);
    if (!is_local_host(def->host, this_host_names))
      throw std::invalid_argument("service " + name + " is placed on host " + def->host +
                                  ", not this one: start it there with the same file, or pass --host " + def->host);
  }
  const auto closure = with_dependencies(graph, selected);
  std::vector<Supervision::Entry> plan;
  for (const auto& name : closure) {
    const auto* def = file.find(name);
    if (is_local_host(def->host, this_host_names)) {
      plan.push_back({def, true});
      continue;
    }
    // A remote service matters here only when something started here waits for it.
    const bool needed = std::any_of(closure.begin(), closure.end(), [&](const std::string& other) {
      const auto* o = file.find(other);
      return is_local_host(o->host, this_host_names) &&
             std::find(o->depends_on.begin(), o->depends_on.end(), name) != o->depends_on.end();
    });
    if (needed) plan.push_back({def, false});
  }
  return plan;
}

}  // namespace rigger::compose
