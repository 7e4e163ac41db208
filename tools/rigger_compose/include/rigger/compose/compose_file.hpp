#pragma once
/// @file
/// The compose file (deploy/compose.yaml): which services make a rigger cell, on which host each runs,
/// with which arguments, configuration, DDS settings and restart policy. Parsed once, validated
/// completely: every error names the file, the line, the key path and what was expected. Format
/// reference: docs/deploy.md.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rigger::compose {

/// What the supervisor does when a service ends on its own (not asked to stop).
enum class RestartPolicy {
  kAlways,     ///< restart whatever the exit status
  kOnFailure,  ///< restart unless it exited with code 0
  kNo,         ///< never restart
};

const char* to_string(RestartPolicy policy);

/// One entry of `services:`. Paths are absolute after parsing.
struct ServiceDef {
  std::string name;                ///< the map key; also the service's DDS id (--id)
  std::string binary;              ///< absolute path of the executable
  std::vector<std::string> args;   ///< extra arguments, after --id/--domain/--config
  std::string config;              ///< absolute path passed as --config; empty: none
  std::string host = "localhost";  ///< the host it runs on (see is_local_host)
  RestartPolicy restart = RestartPolicy::kOnFailure;
  std::vector<std::string> depends_on;             ///< services that must be READY before this one starts
  std::chrono::milliseconds ready_timeout{10000};  ///< spawn → READY announcement
  std::chrono::milliseconds stop_timeout{5000};    ///< SIGINT → exit, then SIGKILL
  std::map<std::string, std::string> env;          ///< added to the environment
  std::string description;
  int line = 0;  ///< 1-based line of its definition, for messages
};

/// A whole compose file.
struct ComposeFile {
  std::string path;  ///< absolute path of the file
  std::string root;  ///< absolute directory that relative paths are resolved against
  std::uint32_t domain = 0;
  std::string dds_config;            ///< absolute path of the Cyclone DDS XML; empty: inherit CYCLONEDDS_URI
  std::string log_dir;               ///< absolute; default /tmp/rigger-compose/<domain>
  std::string bin_dir;               ///< absolute; where bare binary names are looked up
  std::vector<ServiceDef> services;  ///< in file order

  /// The service named `name`, or nullptr.
  const ServiceDef* find(const std::string& name) const;
  /// `path` relative to root when it lies inside it (for messages), else `path` unchanged.
  std::string display_path(const std::string& path) const;
  /// file://<dds_config>, or empty.
  std::string dds_uri() const;
};

/// A problem in a compose file: "<file>:<line>: <key path>: <problem>".
class ComposeError : public std::runtime_error {
 public:
  ComposeError(const std::string& file, int line, const std::string& key_path, const std::string& problem);
  const std::string& file() const { return file_; }
  int line() const { return line_; }  ///< 1-based; 0 when unknown
  const std::string& key_path() const { return key_path_; }

 private:
  std::string file_;
  int line_;
  std::string key_path_;
};

/// Looks an environment variable up (for ${VAR} expansion); nullopt when unset.
using EnvLookup = std::function<std::optional<std::string>(const std::string&)>;

/// The process environment.
std::optional<std::string> process_env(const std::string& name);

struct ParseOptions {
  std::optional<std::uint32_t> domain;  ///< overrides dds.domain (and the default log_dir with it)
  /// bin_dir when the file sets none (absolute); empty: <root>/build/bin. rigger-compose gives its own
  /// folder: the services are built and installed beside it.
  std::string default_bin_dir;
  EnvLookup env = process_env;
};

/// Parses compose YAML `text`; `path` is the file it came from (names it in errors; relative paths in
/// the file resolve against `root:`, itself relative to the file's folder, default ".."). Checks keys,
/// types, ranges, names, dependencies (unknown or cyclic). Does not look at the file system beyond
/// making paths absolute: the `up` command checks that binaries and configurations exist.
/// @throws ComposeError.
ComposeFile parse_compose(const std::string& text, const std::string& path, const ParseOptions& options = {});

/// Reads and parses the file at `path`. @throws ComposeError (also when it cannot be read).
ComposeFile load_compose(const std::string& path, const ParseOptions& options = {});

/// Expands ${NAME}, ${NAME:-default} and $$ in `value`. @throws std::invalid_argument naming the
/// variable when it is unset and has no default, or when the syntax is broken.
std::string expand_variables(const std::string& value, const EnvLookup& env);

/// Whether a service placed on `host` runs on this machine: "localhost", "127.0.0.1", or one of
/// `this_host_names` (e.g. the --host option and the machine's host name, short and full).
bool is_local_host(const std::string& host, const std::vector<std::string>& this_host_names);

}  // namespace rigger::compose
