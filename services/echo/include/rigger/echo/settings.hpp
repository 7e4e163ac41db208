#pragma once
/// @file
/// The echo service's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#echo). The settings struct itself is the
/// service's own (echo_node.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::echo {

struct EchoSettings;

/// The echo service's configuration keys: type, default, range and meaning of each.
const SettingsTable<EchoSettings>& echo_settings();

}  // namespace rigger::echo
