#pragma once
/// @file
/// The supervisor's status file, <log_dir>/status.json: what it runs, rewritten (atomically) on every
/// change. `ps` merges it with what DDS shows; `down` and `restart` read PIDs from it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rigger/compose/supervision.hpp"

namespace rigger::compose {

/// One service in the status file. Times are Unix epoch milliseconds (0: never).
struct ServiceStatusEntry {
  std::string name;
  std::string host;
  bool local = true;
  std::string state;  ///< to_string(ServiceState)
  int pid = 0;
  int restarts = 0;
  std::int64_t started_unix_ms = 0;
  std::int64_t ready_unix_ms = 0;
  std::int64_t next_start_unix_ms = 0;  ///< in backoff: when it starts again
  std::string last_exit;
};

/// The whole status file.
struct SupervisorStatus {
  int supervisor_pid = 0;
  std::uint32_t domain = 0;
  std::string compose_file;
  std::string log_dir;
  std::string phase;    ///< to_string(Phase)
  std::string failure;  ///< why the bring-up failed, if it did
  std::int64_t started_unix_ms = 0;
  std::int64_t updated_unix_ms = 0;
  std::vector<ServiceStatusEntry> services;

  const ServiceStatusEntry* find(const std::string& name) const;
};

/// Converts the supervision's view; steady-clock times become wall-clock times via `steady_now`/`unix_now_ms`.
SupervisorStatus make_status(const Supervision& supervision, Clock::time_point steady_now, std::int64_t unix_now_ms);

std::string to_json_text(const SupervisorStatus& status);
/// @throws std::runtime_error naming what is wrong with `text`.
SupervisorStatus status_from_json_text(const std::string& text);

/// Writes `status` to `path` through a temporary file and rename(), so readers never see half a file.
/// Returns false (and leaves the old file) when it cannot write.
bool write_status_file(const std::string& path, const SupervisorStatus& status);
/// The status at `path`; nullopt when the file does not exist or cannot be parsed.
std::optional<SupervisorStatus> read_status_file(const std::string& path);

/// Milliseconds since the Unix epoch.
std::int64_t unix_now_ms();

}  // namespace rigger::compose
