#pragma once
/// @file
/// The crane gateway's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#crane_gateway). The settings struct itself is
/// the service's own (crane_gateway_node.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::crane_gateway {

struct GatewaySettings;

/// The crane gateway's configuration keys: type, default, range and meaning of each.
const SettingsTable<GatewaySettings>& gateway_settings();

}  // namespace rigger::crane_gateway
