#pragma once
/// @file
/// The built-in skills are written against the public skill SDK (common/skill_sdk), as an integrator's
/// own skills are, and use its names unqualified.

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "rigger/skill_sdk/states.hpp"

namespace rigger::skill_executor {
using namespace rigger::skill_sdk;
}  // namespace rigger::skill_executor
