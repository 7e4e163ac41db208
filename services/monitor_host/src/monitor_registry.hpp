#pragma once
/// @file
/// The monitors a monitor_host offers, by name, and their skill-library document.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "monitor.hpp"
#include "rigger/monitor_host/library.hpp"  // monitor_library_json()

namespace rigger::monitor {

/// Names of every monitor type, sorted: "ForceMonitor", "TimerMonitor", "YankMonitor".
std::vector<std::string> monitor_names();

/// A new, disarmed monitor of type `name`; nullptr for an unknown name.
std::unique_ptr<Monitor> make_monitor(std::string_view name);


}  // namespace rigger::monitor
