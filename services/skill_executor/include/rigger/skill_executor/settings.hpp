#pragma once
/// @file
/// The skill executor's configuration keys, public for the configuration reference
/// (tools/update-config-reference, docs/config-reference.md#skill_executor): the skill SDK's executor
/// keys over the built-in skills.

#include <string>

#include "rigger/skill_sdk/executor_settings.hpp"

namespace rigger::skill_executor {

/// The skill executor's configuration keys; `service_id` (--id) is the default executor id.
SettingsTable<skill_sdk::ExecutorSettings> skill_executor_settings(const std::string& service_id);

}  // namespace rigger::skill_executor
