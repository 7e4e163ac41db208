#pragma once
/// @file
/// The scripted executor's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#scripted_executor). The settings struct
/// itself is the service's own (scripted_settings.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::scripted {

struct ScriptedExecutorSettings;

/// The scripted executor's configuration keys: type, default, range and meaning of each.
const SettingsTable<ScriptedExecutorSettings>& scripted_executor_settings();

}  // namespace rigger::scripted
