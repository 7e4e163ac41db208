#include "controller_settings.hpp"

#include "rigger/dds/qos.hpp"

namespace rigger::task_controller {
namespace {

/// A duration key in seconds, in [lo, hi].
std::chrono::nanoseconds seconds_in_range(const Config& config, const std::string& key, double fallback, double lo,
                                          double hi) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(config.get_in_range<double>(key, fallback, lo, hi)));
}

}  // namespace

ControllerSettings read_settings(const Config& config, const std::string& journal_path) {
  ControllerSettings s;
  s.journal_path = config.get<std::string>("journal_path", s.journal_path);
  if (!journal_path.empty()) s.journal_path = journal_path;
  s.journal_sync =
      config.get_enum("journal_sync", "normal", {"normal", "full"}) == "full" ? JournalSync::kFull : JournalSync::kNormal;
  s.command_lease = std::chrono::milliseconds(config.get_in_range<unsigned>(
      "command_lease_ms", static_cast<unsigned>(dds::liveliness_lease().count()), 100U, 10000U));
  s.validator.default_stop_timeout =
      bt::Seconds(config.get_in_range<double>("default_stop_timeout_s", 5.0, 0.01, 600.0));
  s.validator.limits.max_bytes = config.get_in_range<unsigned>(
      "max_recipe_bytes", 4U * 1024U * 1024U, 1024U, static_cast<unsigned>(recipe::kMaxRecipeBytesCeiling));
  s.validator.limits.max_depth = config.get_in_range<unsigned>("max_recipe_depth", 128U, 8U, 1024U);
  s.executor_wait = seconds_in_range(config, "executor_wait_s", 2.0, 0.0, 600.0);
  s.condition_timeout =
      std::chrono::milliseconds(config.get_in_range<unsigned>("condition_timeout_ms", 1000U, 10U, 60000U));
  s.start_answer_timeout = seconds_in_range(config, "start_answer_timeout_s", 5.0, 0.05, 600.0);
  s.start_resend = seconds_in_range(config, "start_resend_s", 0.2, 0.01, 60.0);
  s.busy_wait = seconds_in_range(config, "busy_wait_s", 10.0, 0.0, 600.0);
  s.progress_rows_per_run = config.get_in_range<unsigned>("journal_progress_per_run", 20U, 0U, 100000U);
  s.flush_delay = std::chrono::microseconds(config.get_in_range<unsigned>("flush_delay_us", 1000U, 0U, 100000U));
  s.stage_trace_path = config.get<std::string>("stage_trace_path", "");
  s.recheck.tolerance_m = config.get_in_range<double>("resume_tolerance_mm", 10.0, 0.1, 10000.0) / 1000.0;
  s.recheck.tolerance_deg = config.get_in_range<double>("resume_tolerance_deg", 2.0, 0.01, 180.0);
  s.recheck.max_age_s = config.get_in_range<double>("resume_max_pose_age_s", 300.0, 0.1, 1e6);
  config.finish();
  return s;
}

}  // namespace rigger::task_controller
