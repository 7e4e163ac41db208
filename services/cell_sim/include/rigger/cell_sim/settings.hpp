#pragma once
/// @file
/// The cell simulator's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#cell_sim). The settings struct itself is the
/// service's own (cell_sim_config.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::cell_sim {

struct CellSimConfig;

/// The cell simulator's configuration keys: type, default, range and meaning of each.
const SettingsTable<CellSimConfig>& cell_sim_settings();

}  // namespace rigger::cell_sim
