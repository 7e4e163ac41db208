#pragma once
/// @file
/// The supervisor process: carries out the decisions of Supervision (supervision.hpp) with real
/// processes and DDS. It owns the domain's lock, writes <log_dir>/supervisor.pid and status.json,
/// starts each service with `--id <name> --domain <d> [--config <file>] <args…>`, CYCLONEDDS_URI and
/// RIGGER_DOMAIN, output appended to <log_dir>/<name>.log, watches READY announcements on
/// rigger/system/service_state, reaps its children on SIGCHLD (signalfd), takes `restart <name>`
/// requests on the FIFO <log_dir>/control, and stops everything on SIGINT, SIGTERM or SIGHUP.
/// It only ever signals processes it started and has not yet reaped.

#include <string>
#include <vector>

#include "rigger/base/logging.hpp"
#include "rigger/compose/compose_file.hpp"

namespace rigger::compose {

struct SupervisorOptions {
  std::vector<std::string> services;         ///< `up` arguments; empty: every service of this host
  std::vector<std::string> this_host_names;  ///< see this_host_names()
  std::string host;                          ///< the explicit host name (--host, $RIGGER_HOST) or empty
  /// Where progress goes for the `up` command waiting on it: lines "I text", "W text", "E text",
  /// then "OK" once every service is READY (the descriptor is then closed). -1: none.
  int notify_fd = -1;
  /// The services stay in the supervisor's process group instead of each leading one: whoever made that
  /// group (the console, for its rehearsal cell) ends every service with it by the group id, also when the
  /// supervisor was SIGKILLed and could not stop them. Only for a supervisor that leads a group of its
  /// own: a terminal's Ctrl-C would then reach the services past the stop order.
  bool services_in_group = false;
};

/// Runs until every service has stopped. Returns 0 after a clean stop, 1 when the bring-up failed or
/// the supervisor could not start (the reason went to `notify_fd` and the log), 2 for a bad selection.
int run_supervisor(const ComposeFile& file, const SupervisorOptions& options, const Logger& log);

}  // namespace rigger::compose
