#pragma once
/// @file
/// The task controller's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#task_controller). The settings struct itself is the
/// service's own (controller_settings.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::task_controller {

struct ControllerSettings;

/// The task controller's configuration keys: type, default, range and meaning of each.
const SettingsTable<ControllerSettings>& controller_settings();

}  // namespace rigger::task_controller
