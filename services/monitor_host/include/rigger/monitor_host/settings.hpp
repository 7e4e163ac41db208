#pragma once
/// @file
/// The monitor host's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#monitor_host).

#include <cstddef>
#include <string>

#include "rigger/base/settings.hpp"

namespace rigger::monitor {

/// The monitor host's configuration.
struct MonitorHostSettings {
  std::string executor_id;
  std::size_t max_monitors{};
  std::string wrench_topic;
};

/// The monitor host's configuration keys; `service_id` (--id) is the default executor id.
SettingsTable<MonitorHostSettings> monitor_host_settings(const std::string& service_id);

}  // namespace rigger::monitor
