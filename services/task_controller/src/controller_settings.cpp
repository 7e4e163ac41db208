#include "controller_settings.hpp"

#include "rigger/dds/qos.hpp"

namespace rigger::task_controller {
namespace {

// The lease of the process ($RIGGER_LIVELINESS_LEASE_MS may change it), read when the settings are.
unsigned process_lease_ms() {
  return static_cast<unsigned>(dds::liveliness_lease().count());
}

}  // namespace

const SettingsTable<ControllerSettings>& controller_settings() {
  using S = ControllerSettings;
  static const SettingsTable<S> table{
      setting<S>("journal_path", "task_controller_journal.sqlite", &S::journal_path,
                 "the SQLite journal; its folder is created on first use (the shipped file uses "
                 "`/var/tmp/rigger/`); the `--journal` option takes its place"),
      choice<S>("journal_sync", JournalSync::kNormal, {{"normal", JournalSync::kNormal}, {"full", JournalSync::kFull}},
                &S::journal_sync,
                "`normal`: no fsync per commit, so journal rows survive controller crashes and restarts, but an OS "
                "crash or power cut may lose the last commits; `full`: an fsync per commit, so rows also survive a "
                "power cut. The rows are written after the commands they accompany, so `full` costs no reaction "
                "time ([decision 0004](decisions/0004-reaction-latency.md))"),
      setting<S>(
          "default_stop_timeout_s", 5.0, {0.01, 600.0},
          [](S& s, double v) { s.validator.default_stop_timeout = bt::Seconds(v); },
          "a leaf's stop timeout when the recipe gives none"),
      setting<S>(
          "max_recipe_bytes", 4U * 1024U * 1024U, {1024U, static_cast<unsigned>(recipe::kMaxRecipeBytesCeiling)},
          [](S& s, unsigned v) { s.validator.limits.max_bytes = v; }, "a recipe's size, bounded while parsing"),
      setting<S>(
          "max_recipe_depth", 128U, {8U, 1024U}, [](S& s, unsigned v) { s.validator.limits.max_depth = v; },
          "a recipe's nesting, bounded while parsing"),
      setting<S>(
          "max_recipe_nodes", 50000U, {100U, 1000000U}, [](S& s, unsigned v) { s.validator.limits.max_nodes = v; },
          "a recipe's behaviour-tree nodes, bounded while parsing"),
      setting<S>("executor_wait_s", 2.0, {0.0, 600.0}, &S::executor_wait,
                 "how long a recipe naming a skill no live executor offers waits for one to appear (re-validated "
                 "on every new announcement) before it is rejected"),
      setting<S>("start_answer_timeout_s", 5.0, {0.05, 600.0}, &S::start_answer_timeout,
                 "an executor answers every START at once (ACCEPTED, or FAILURE with a code); a START without an "
                 "answer in this time fails its leaf with `START_UNANSWERED` (and the controller sends a SHUTDOWN "
                 "after it)"),
      setting<S>("start_resend_s", 0.2, {0.01, 60.0}, &S::start_resend,
                 "a START still unanswered after this long is sent again with its seq on the same writer (journal "
                 "`COMMAND START_SENT_AGAIN`), then after 2× and 4× this long, while `start_answer_timeout_s` "
                 "lasts; an executor takes each seq once "
                 "([dds.md](dds.md#a-command-written-too-early-reaches-nobody))"),
      setting<S>("busy_wait_s", 10.0, {0.0, 600.0}, &S::busy_wait,
                 "how long a START is held while a run of another task holds one of the leaf's resources, as the "
                 "executors announce their runs (after a controller restart: the killed controller's runs, still "
                 "stopping); re-checked on every announcement, then the leaf fails `RESOURCE_HELD` naming the "
                 "holder ([safety.md](safety.md))"),
      setting<S>("journal_progress_per_run", 20U, {0U, 100000U}, &S::progress_rows_per_run,
                 "how many PROGRESS events of each run of a leaf are journaled (`EVENT PROGRESS`, \"fraction: "
                 "message\"); when the run ends one row `EVENT PROGRESS_LEFT_OUT` counts the others"),
      setting<S>("command_lease_ms",
                 RuntimeDefault<unsigned>{&process_lease_ms, std::to_string(dds::kDefaultLease.count())},
                 {100U, 10000U}, &S::command_lease,
                 "the liveliness lease the controller offers on `rigger/skill/command`; the default is the "
                 "process's lease, `$RIGGER_LIVELINESS_LEASE_MS` where it is set. Executors watch it: when the "
                 "controller is killed or stops, each executor shuts down the runs that controller started (reason "
                 "`CONTROLLER_LOST`), so no skill keeps a robot or crane moving without a supervisor; a controller "
                 "whose work loop hangs loses it after the loop stall limit (1 s) plus the lease. The liveliness is "
                 "asserted from a thread of its own every third of this lease or of the service lease (150 ms), "
                 "whichever is shorter ([dds.md](dds.md))"),
      setting<S>("flush_delay_us", 1000U, {0U, 100000U}, &S::flush_delay,
                 "the journal rows and node statuses an event causes are handed to the controller's writer thread "
                 "this long after its commands, in one transaction with those of every event that comes meanwhile; "
                 "0: right after the handler. A kill loses at most the groups not yet written (normally the last) "
                 "([where the time goes](behavior-tree.md#where-the-time-goes))"),
      setting<S>("condition_timeout_ms", 1000U, {10U, 60000U}, &S::condition_timeout,
                 "how long a Condition, the pose journaled after a localization, and the resume's re-check of the "
                 "world wait for the world model's answer (then `WORLD_UNREACHABLE`)"),
      setting<S>(
          "resume_tolerance_mm", 10.0, {0.1, 10000.0}, [](S& s, double mm) { s.recheck.tolerance_m = mm / 1000.0; },
          "resume after a crash: a completed localization runs again when its object is farther than this "
          "from the pose journaled when it was localized "
          "([resume after a crash](behavior-tree.md#resume-after-a-crash))"),
      setting<S>(
          "resume_tolerance_deg", 2.0, {0.01, 180.0}, [](S& s, double v) { s.recheck.tolerance_deg = v; },
          "… or turned by more than this"),
      setting<S>(
          "resume_max_pose_age_s", 300.0, {0.1, 1e6}, [](S& s, double v) { s.recheck.max_age_s = v; },
          "… or when the object's pose is older than this (a recipe's `ObjectLocalized(object, "
          "max_age_s)` asks for less)"),
      setting<S>("stage_trace_path", "", &S::stage_trace_path,
                 "empty: off. Record, per executor event, when it was received, its first command written, the "
                 "engine done and its journal rows flushed, and write them to this file when the controller stops; "
                 "and every dispatch of its work loop (and each flush) to this file + `.loop` "
                 "(`task_controller_live_bench` reads both)"),
  };
  return table;
}

ControllerSettings read_settings(const Config& config, const std::string& journal_path) {
  ControllerSettings s = rigger::read_settings(config, controller_settings());
  if (!journal_path.empty()) s.journal_path = journal_path;
  return s;
}

}  // namespace rigger::task_controller
