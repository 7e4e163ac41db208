#pragma once
/// @file
/// The skills built into the skill_executor binary. They are written against the public skill SDK
/// (common/skill_sdk) exactly as an integrator's own skills are.

#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_executor {

using skill_sdk::SkillRegistry;

/// The registry of every skill built into this binary.
SkillRegistry builtin_skills();

}  // namespace rigger::skill_executor
