#pragma once
/// @file
/// The world model's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#world_model). The settings struct itself is the
/// service's own (world_model_node.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::world {

struct WorldModelSettings;

/// The world model's configuration keys: type, default, range and meaning of each.
const SettingsTable<WorldModelSettings>& world_model_settings();

}  // namespace rigger::world
