#pragma once
/// @file
/// The monitor host's public face to other programs (the skill catalog, tools/update-skill-library): the
/// skill-library document of its monitors. Everything else of the monitor host is private.

#include <nlohmann/json.hpp>

namespace rigger::monitor {

/// `{ "library_version": 1, "skills": [ description of each monitor ] }`, as a monitor host announces it.
nlohmann::json monitor_library_json();

}  // namespace rigger::monitor
