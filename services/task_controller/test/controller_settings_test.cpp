#include "controller_settings.hpp"

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

using namespace std::chrono_literals;

TEST(ControllerSettingsTest, DefaultsWithoutKeys) {
  const ControllerSettings s = read_settings(Config::empty());
  EXPECT_EQ(s.journal_path, "task_controller_journal.sqlite");
  EXPECT_EQ(s.journal_sync, JournalSync::kNormal);
  EXPECT_EQ(s.command_lease, dds::liveliness_lease());  // 150 ms unless $RIGGER_LIVELINESS_LEASE_MS
  EXPECT_EQ(s.executor_wait, 2s);
  EXPECT_EQ(s.condition_timeout, 1000ms);
  EXPECT_EQ(s.start_answer_timeout, 5s);
  EXPECT_EQ(s.busy_wait, 10s);
  EXPECT_EQ(s.progress_rows_per_run, 20u);
  EXPECT_EQ(s.validator.limits.max_depth, 128u);
  EXPECT_TRUE(s.stage_trace_path.empty());
  EXPECT_DOUBLE_EQ(s.recheck.tolerance_m, 0.010);
  EXPECT_DOUBLE_EQ(s.recheck.tolerance_deg, 2.0);
  EXPECT_DOUBLE_EQ(s.recheck.max_age_s, 300.0);
}

TEST(ControllerSettingsTest, ReadsEveryKey) {
  const ControllerSettings s = read_settings(Config::parse(R"({
    "journal_path": "/tmp/j.sqlite", "journal_sync": "full", "command_lease_ms": 200,
    "default_stop_timeout_s": 2.5, "max_recipe_bytes": 2048, "max_recipe_depth": 16,
    "executor_wait_s": 0, "condition_timeout_ms": 50, "start_answer_timeout_s": 0.25, "busy_wait_s": 1,
    "journal_progress_per_run": 0, "stage_trace_path": "/tmp/trace", "resume_tolerance_mm": 25,
    "resume_tolerance_deg": 5, "resume_max_pose_age_s": 60})",
                                                           "tc.json"));
  EXPECT_EQ(s.journal_path, "/tmp/j.sqlite");
  EXPECT_EQ(s.journal_sync, JournalSync::kFull);
  EXPECT_EQ(s.command_lease, 200ms);
  EXPECT_DOUBLE_EQ(s.validator.default_stop_timeout.count(), 2.5);
  EXPECT_EQ(s.validator.limits.max_bytes, 2048u);
  EXPECT_EQ(s.validator.limits.max_depth, 16u);
  EXPECT_EQ(s.executor_wait, 0s);
  EXPECT_EQ(s.condition_timeout, 50ms);
  EXPECT_EQ(s.start_answer_timeout, 250ms);
  EXPECT_EQ(s.busy_wait, 1s);
  EXPECT_EQ(s.progress_rows_per_run, 0u);
  EXPECT_EQ(s.stage_trace_path, "/tmp/trace");
  EXPECT_DOUBLE_EQ(s.recheck.tolerance_m, 0.025);
  EXPECT_DOUBLE_EQ(s.recheck.tolerance_deg, 5.0);
  EXPECT_DOUBLE_EQ(s.recheck.max_age_s, 60.0);
}

TEST(ControllerSettingsTest, RefusesOutOfRangeAndUnknownKeys) {
  EXPECT_THROW(read_settings(Config::parse(R"({"command_lease_ms": 50})", "tc.json")), ConfigError);
  EXPECT_THROW(read_settings(Config::parse(R"({"journal_sync": "sometimes"})", "tc.json")), ConfigError);
  EXPECT_THROW(read_settings(Config::parse(R"({"resume_tolerance_mm": 0})", "tc.json")), ConfigError);
  try {
    read_settings(Config::parse(R"({"busy_wait": 3})", "tc.json"));
    FAIL() << "an unknown key was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("busy_wait"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigger::task_controller
