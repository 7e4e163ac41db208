#include "rigger/dds/configuration.hpp"

#include <cstdlib>
#include <mutex>
#include <system_error>

#include "rigger/base/install.hpp"

namespace rigger::dds {

DdsConfiguration resolve_configuration(const char* env_uri, const std::filesystem::path& data_dir) {
  if (env_uri && *env_uri) return {env_uri, ConfigurationOrigin::kEnvironment};
  if (!data_dir.empty()) {
    const auto file = data_dir / "cyclonedds.xml";
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec))
      return {"file://" + std::filesystem::weakly_canonical(file, ec).string(), ConfigurationOrigin::kInstallation};
  }
  return {"", ConfigurationOrigin::kCycloneDefaults};
}

const DdsConfiguration& configuration() {
  static std::once_flag once;
  static DdsConfiguration config;
  std::call_once(once, [] {
    config = resolve_configuration(std::getenv("CYCLONEDDS_URI"), data_dir());
    // Set before any participant exists (this runs in the first Participant's constructor), so Cyclone
    // reads it when it creates the domain; overwrite=0 keeps a value another thread set meanwhile.
    if (config.origin == ConfigurationOrigin::kInstallation) setenv("CYCLONEDDS_URI", config.uri.c_str(), 0);
  });
  return config;
}

std::string describe_domain(std::uint32_t domain) {
  const auto& c = configuration();
  std::string text = "domain " + std::to_string(domain) + " (DDS configuration ";
  switch (c.origin) {
    case ConfigurationOrigin::kEnvironment:
      text += c.uri + " from CYCLONEDDS_URI";
      break;
    case ConfigurationOrigin::kInstallation:
      text += c.uri + " from the installation";
      break;
    case ConfigurationOrigin::kCycloneDefaults:
      text += "Cyclone's built-in defaults: CYCLONEDDS_URI is unset and " + (data_dir() / "cyclonedds.xml").string() +
              " does not exist";
      break;
  }
  return text + ")";
}

}  // namespace rigger::dds
