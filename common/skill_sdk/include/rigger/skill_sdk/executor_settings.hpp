#pragma once
/// @file
/// The configuration keys of a skill executor (run_executor()): which of its skills it announces, under
/// which id, and which cell devices it connects to. A program built on the SDK reads the same keys as
/// the repository's skill_executor (docs/config-reference.md#skill_executor).

#include <chrono>
#include <string>
#include <vector>

#include "rigger/base/settings.hpp"
#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_sdk {

/// A skill executor's configuration.
struct ExecutorSettings {
  std::string executor_id;
  std::vector<std::string> skills;  ///< the announced ones, each in the registry
  bool robot{};
  bool gripper{};
  bool world_model{};
  bool crane{};
  bool tracker{};
  bool admittance{};
  bool operator_panel{};
  std::string resolve_frame;
  std::chrono::nanoseconds resolve_timeout{};
};

/// The configuration keys of an executor of `registry`'s skills; `service_id` (--id) is the default
/// executor id.
SettingsTable<ExecutorSettings> executor_settings(const std::string& service_id, const SkillRegistry& registry);

}  // namespace rigger::skill_sdk
