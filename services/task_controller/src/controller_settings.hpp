#pragma once
/// @file
/// The task controller's configuration, read once before the node builds anything (the journal, the
/// command writer's lease and the validator depend on it), apart from the node so that it is read and
/// checked without DDS.
///
/// Every key is optional; each is declared once, in controller_settings(), which also writes
/// docs/config-reference.md#task_controller (tools/update-config-reference).

#include <chrono>
#include <string>

#include "journal.hpp"
#include "relocalization.hpp"
#include "rigger/base/config.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/task_controller/settings.hpp"

namespace rigger::task_controller {

/// The configuration, as typed values (durations in the units of their keys' names); the defaults are
/// those of controller_settings().
struct ControllerSettings {
  std::string journal_path;
  JournalSync journal_sync{};
  std::chrono::milliseconds command_lease{};
  recipe::ValidatorOptions validator;  ///< default_stop_timeout_s, max_recipe_bytes, max_recipe_depth
  std::chrono::nanoseconds executor_wait{};
  std::chrono::milliseconds condition_timeout{};
  std::chrono::nanoseconds start_answer_timeout{};
  std::chrono::nanoseconds start_resend{};
  std::chrono::nanoseconds busy_wait{};
  unsigned progress_rows_per_run{};
  std::chrono::microseconds flush_delay{};
  std::string stage_trace_path;  ///< empty: no stage trace
  RecheckSettings recheck;       ///< resume_tolerance_mm, resume_tolerance_deg, resume_max_pose_age_s
};

/// Reads every key, then config.finish(); a non-empty `journal_path` (the --journal option) takes the
/// place of the configured one. @throws ConfigError naming the key and what was expected.
ControllerSettings read_settings(const Config& config, const std::string& journal_path = "");

}  // namespace rigger::task_controller
