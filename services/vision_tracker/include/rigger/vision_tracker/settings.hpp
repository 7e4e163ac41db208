#pragma once
/// @file
/// The vision tracker's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#vision_tracker). The settings struct itself is the
/// service's own (vision_tracker_node.hpp).

#include "rigger/base/settings.hpp"

namespace rigger::vision {

struct VisionTrackerSettings;

/// The vision tracker's configuration keys: type, default, range and meaning of each.
const SettingsTable<VisionTrackerSettings>& vision_tracker_settings();

}  // namespace rigger::vision
