#pragma once
/// @file
/// The console's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#console).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rigger/base/settings.hpp"

namespace rigger::console {

/// The console's configuration.
struct ConsoleSettings {
  std::string address;
  int port{};
  std::string web_dir;
  std::string audit_log;  ///< empty: actions are only logged
  std::string tls_cert;   ///< with tls_key: HTTPS
  std::string tls_key;
  std::chrono::milliseconds confirm_timeout{};
  std::size_t max_body_bytes{};
  std::string users_file;
  double plot_rate_hz{};
  std::chrono::milliseconds query_timeout{};
  std::optional<std::uint32_t> rehearsal_domain;  ///< none: no rehearsal
  // The rehearsal cell on demand (rehearsal_launcher.hpp): none without a start command.
  std::vector<std::string> rehearsal_start;  ///< argv; empty: the rehearsal cell is started by hand
  std::vector<std::string> rehearsal_env;    ///< "NAME=value" for the start command
  std::string rehearsal_cell_folder;         ///< the rehearsal cell's own cell folder; empty: not known
  std::string rehearsal_log;
  std::chrono::milliseconds rehearsal_start_timeout{};
  std::chrono::milliseconds rehearsal_idle_stop{};
  std::chrono::milliseconds rehearsal_stop_timeout{};
  std::string runs_dir;                           ///< empty: runs are not kept
  std::size_t max_runs{};
  int max_streams{};  ///< live (SSE) streams served at once
  std::size_t max_import_bytes{};  ///< a STEP file sent to the Planner's import
};

/// The console's configuration keys.
const SettingsTable<ConsoleSettings>& console_settings();

/// Reads the console's keys and refuses unknown ones and a lone tls_cert or tls_key. @throws ConfigError.
ConsoleSettings read_console_settings(const Config& config);

}  // namespace rigger::console
