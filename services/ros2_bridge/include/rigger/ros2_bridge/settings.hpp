#pragma once
/// @file
/// The ROS 2 bridge's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#ros2_bridge). The settings struct itself is the
/// service's own (bridge_config.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::ros2_bridge {

struct BridgeConfig;

/// The bridge's configuration keys: type, default, range and meaning of each. The rules that relate several
/// keys (topic names in `ros_namespace`, at least one stream, one topic per stream) are read_bridge_config()'s.
const SettingsTable<BridgeConfig>& bridge_settings();

}  // namespace rigger::ros2_bridge
