#pragma once
/// @file
/// The scripted operator's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#scripted_operator). The settings struct
/// itself is the service's own (rules.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::scripted_operator {

struct ScriptedOperatorSettings;

/// The scripted operator's configuration keys: type, default, range and meaning of each.
const SettingsTable<ScriptedOperatorSettings>& scripted_operator_settings();

}  // namespace rigger::scripted_operator
