#pragma once
/// @file
/// The admittance controller's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#admittance_control). The settings struct
/// itself is the service's own (control_config.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::control {

struct ControlConfig;

/// The admittance controller's configuration keys: type, default, range, unit and meaning of each. The
/// rules that relate several keys are load_control_config()'s.
const SettingsTable<ControlConfig>& control_settings();

}  // namespace rigger::control
