#pragma once
/// @file
/// The task controller's configuration, read once before the node builds anything (the journal, the
/// command writer's lease and the validator depend on it), apart from the node so that it is read and
/// checked without DDS.
///
/// The task controller's configuration keys (all optional):
///   "journal_path": string, default "task_controller_journal.sqlite"
///   "journal_sync": "normal" (default: no fsync per commit; survives controller crashes and restarts) or
///                   "full" (an fsync per commit; also survives a power cut). See journal.hpp.
///   "default_stop_timeout_s": number in [0.01, 600], default 5
///   "max_recipe_bytes": integer in [1024, 67108864 (recipe::kMaxRecipeBytesCeiling)], default 4194304
///   "max_recipe_depth": integer in [8, 1024], default 128
///   "command_lease_ms": integer in [100, 10000], default dds::liveliness_lease() (150): the liveliness
///                       lease offered on rigger/skill/command; executors shut down the runs of a
///                       controller that lost it
///   "stage_trace_path": string, default "" (off): record when each executor event was received, its first
///                       command written, the engine done and its side effects flushed (StageTrace), and
///                       write the records to this file when the controller stops (for the live bench)
///   "executor_wait_s": number in [0, 600], default 2: a recipe naming a skill no live executor offers
///                      waits this long for one to appear (re-validated on every new announcement)
///                      before it is rejected
///   "condition_timeout_ms": integer in [10, 60000], default 1000: how long a Condition waits for the
///                      world model's answer before it fails WORLD_UNREACHABLE
///   "start_answer_timeout_s": number in [0.05, 600], default 5: an executor answers every START at once
///                      (ACCEPTED, or FAILURE with a code); a START without an answer in this time fails
///                      its leaf with START_UNANSWERED (and the controller sends a SHUTDOWN after it)
///   "start_resend_s": number in [0.01, 60], default 0.2: a START still unanswered after this long is
///                      sent again (same seq, same writer), and again after twice and four times this
///                      long, while start_answer_timeout_s lasts
///   "busy_wait_s": number in [0, 600], default 10: a START whose resources a run of another task holds
///                      (as the executors announce their runs: a killed controller's, still stopping) is
///                      held until they are free, re-checked on every announcement; after this long the
///                      leaf fails RESOURCE_HELD, naming the holder
///   "journal_progress_per_run": integer in [0, 100000], default 20: the first PROGRESS events of each
///                      run are journaled; at the run's end one row (PROGRESS_LEFT_OUT) counts the others
///   "flush_delay_us": integer in [0, 100000], default 1000: the journal rows and node statuses an event
///                      causes are written this long after its commands, together with those of every
///                      event that comes meanwhile; the commands' receivers get the CPU first (on a
///                      2-core machine the flush competed with them), and a burst is one transaction.
///                      0: right after the handler (docs/behavior-tree.md#where-the-time-goes)
///   "resume_tolerance_mm": number in [0.1, 10000], default 10, and "resume_tolerance_deg": number in
///                      [0.01, 180], default 2: a resumed task's completed localization of an object runs
///                      again when the object is farther than this from the pose journaled when it was
///                      localized (relocalization.hpp)
///   "resume_max_pose_age_s": number in [0.1, 1e6], default 300: ... or when its pose is older than this (a
///                      recipe's ObjectLocalized(object, max_age_s) condition asks for less)

#include <chrono>
#include <string>

#include "journal.hpp"
#include "relocalization.hpp"
#include "rigger/base/config.hpp"
#include "rigger/recipe/recipe_validator.hpp"

namespace rigger::task_controller {

/// The keys above, as typed values (durations in the units of their names).
struct ControllerSettings {
  std::string journal_path = "task_controller_journal.sqlite";
  JournalSync journal_sync = JournalSync::kNormal;
  std::chrono::milliseconds command_lease{300};
  recipe::ValidatorOptions validator;  ///< default_stop_timeout_s, max_recipe_bytes, max_recipe_depth
  std::chrono::nanoseconds executor_wait{std::chrono::seconds(2)};
  std::chrono::milliseconds condition_timeout{1000};
  std::chrono::nanoseconds start_answer_timeout{std::chrono::seconds(5)};
  std::chrono::nanoseconds start_resend{std::chrono::milliseconds(200)};
  std::chrono::nanoseconds busy_wait{std::chrono::seconds(10)};
  unsigned progress_rows_per_run = 20;
  std::chrono::microseconds flush_delay{1000};
  std::string stage_trace_path;  ///< empty: no stage trace
  RecheckSettings recheck;       ///< resume_tolerance_mm, resume_tolerance_deg, resume_max_pose_age_s
};

/// Reads every key, then config.finish(); a non-empty `journal_path` (the --journal option) takes the
/// place of the configured one. @throws ConfigError naming the key and what was expected.
ControllerSettings read_settings(const Config& config, const std::string& journal_path = "");

}  // namespace rigger::task_controller
