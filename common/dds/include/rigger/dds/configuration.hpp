#pragma once
/// @file
/// Which Cyclone DDS configuration a rigger process uses, decided in one place for every process.
///
/// `CYCLONEDDS_URI` set (and not empty): respected as is. Unset: the installation's configuration,
/// `<prefix>/share/rigger/cyclonedds.xml` next to the executable's `bin/` (in the build tree, a copy of
/// `deploy/cyclonedds.xml` staged by CMake) — the file `deploy/compose.yaml` gives every service, so a
/// tool started by hand in a plain shell joins the cell that `rigger-compose up` started. Neither: Cyclone's
/// built-in defaults.

#include <cstdint>
#include <filesystem>
#include <string>

namespace rigger::dds {

/// Where the configuration came from.
enum class ConfigurationOrigin { kEnvironment, kInstallation, kCycloneDefaults };

struct DdsConfiguration {
  std::string uri;  ///< what CYCLONEDDS_URI holds for this process; empty for Cyclone's defaults
  ConfigurationOrigin origin = ConfigurationOrigin::kCycloneDefaults;
};

/// Pure decision: `env_uri` is CYCLONEDDS_URI (nullptr: unset); `data_dir` the installation's data
/// folder (rigger::data_dir()). The installation's file is taken only when it exists.
DdsConfiguration resolve_configuration(const char* env_uri, const std::filesystem::path& data_dir);

/// The configuration of this process, decided once (thread-safe). When it is the installation's,
/// CYCLONEDDS_URI is set to it before the first participant is created, so Cyclone and any child process
/// read the same. Called by Participant's constructor; call it earlier only to report it.
const DdsConfiguration& configuration();

/// For messages a person reads: "domain 7 (DDS configuration file:///…/cyclonedds.xml from the
/// installation)" — what a tool that finds nobody must say.
std::string describe_domain(std::uint32_t domain);

}  // namespace rigger::dds
