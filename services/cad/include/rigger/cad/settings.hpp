#pragma once
/// @file
/// The cad service's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#cad). The settings struct itself is the
/// service's own (cad_service.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::cad_service {

struct CadServiceSettings;

/// The cad service's configuration keys: type, default, range and meaning of each.
const SettingsTable<CadServiceSettings>& cad_settings();

}  // namespace rigger::cad_service
