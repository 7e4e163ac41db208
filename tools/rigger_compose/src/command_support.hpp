#pragma once
/// @file
/// What the rigger-compose verbs share (one verb per <verb>_command.cpp, the command line in
/// commands.cpp): the global options, the error a verb raises for its exit code, loading the compose
/// file, and stopping the services a dead supervisor left running.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rigger/compose/compose_file.hpp"
#include "rigger/compose/supervision.hpp"

namespace rigger::compose::cli {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

struct GlobalOptions {
  std::string file;  ///< empty: the installation's deploy/compose.yaml (rigger/base/install.hpp)
  std::optional<std::uint32_t> domain;
  std::string host;
  bool secure = false;  ///< --secure: DDS Security (security.hpp)
};

/// Raised by commands for a clear message and an exit code; caught once in run_cli.
struct CommandError {
  std::string message;
  int code;
};

/// Throws CommandError{message, code}.
[[noreturn]] void fail(const std::string& message, int code = kExitFailure);

/// The compose file of --file (or the installation's), with --domain and --secure applied. Throws
/// ComposeError on a bad file, CommandError when the security files are missing.
ComposeFile load(const GlobalOptions& g);

/// --host, else $RIGGER_HOST, else "" (the machine's names); fails (usage) when it is not a host name.
std::string host_option(const GlobalOptions& g);

/// Seconds from t to now.
double seconds_since(Clock::time_point t);

/// Points CYCLONEDDS_URI at the file's dds.config, when it has one, for this process's participant.
void use_dds_config(const ComposeFile& file);

/// Stops the services a dead supervisor left running (listed in its last status file under log_dir),
/// in reverse start order; returns how many were found.
int stop_orphans(const ComposeFile& file, const std::string& log_dir);

// The verbs; each returns the exit code or throws CommandError.
int up(const GlobalOptions& g, const std::vector<std::string>& services);
int down(const GlobalOptions& g);
int ps(const GlobalOptions& g, bool json, double timeout_s);
int logs(const GlobalOptions& g, const std::string& service, bool follow, int last_lines);
int restart(const GlobalOptions& g, const std::string& service);
int demo(const GlobalOptions& g, const std::string& recipe_arg, const std::string& operator_mode);
int config(const GlobalOptions& g);
int supervise(const GlobalOptions& g, const std::vector<std::string>& services, int notify_fd, bool in_group);

}  // namespace rigger::compose::cli
