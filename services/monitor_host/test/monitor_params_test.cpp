#include <set>

#include <gtest/gtest.h>

#include "force_monitor.hpp"
#include "monitor_registry.hpp"
#include "monitor_test_util.hpp"
#include "timer_monitor.hpp"
#include "yank_monitor.hpp"

namespace rigger::monitor {
namespace {

using nlohmann::json;
using testing::kT0;

// Resets `monitor` with `params` and expects exactly one error containing each of `parts`.
void expect_param_error(Monitor& monitor, const json& params, const std::vector<std::string>& parts) {
  const ParamCheck check = monitor.reset(params, kT0);
  ASSERT_FALSE(check.ok()) << params.dump();
  EXPECT_FALSE(monitor.armed());
  ASSERT_EQ(check.errors.size(), 1u) << check.message();
  for (const auto& part : parts) EXPECT_NE(check.errors[0].find(part), std::string::npos) << check.errors[0];
  const Verdict verdict = monitor.on_time(kT0);
  EXPECT_TRUE(verdict.fired()) << "a monitor that failed to arm must not pass silently";
  EXPECT_EQ(verdict.code, kCodeNotArmed);
}

TEST(MonitorParams, DescriptionsHaveTheSkillLibraryShape) {
  for (const auto& name : monitor_names()) {
    const auto monitor = make_monitor(name);
    ASSERT_NE(monitor, nullptr) << name;
    const json description = monitor->description().to_json();
    EXPECT_EQ(description["name"], name);
    EXPECT_EQ(description["kind"], "monitor");
    EXPECT_TRUE(description["description"].is_string());
    EXPECT_EQ(description["resources"], json::array());
    std::set<std::string> keys;
    for (const auto& item : description.items()) keys.insert(item.key());
    EXPECT_EQ(keys, (std::set<std::string>{"name", "kind", "description", "params", "resources"}));
    ASSERT_FALSE(description["params"].empty());
    for (const auto& param : description["params"]) {
      // The form of rigger::skill::to_json(ParamSpec): optional keys only when they have a value.
      for (const auto& item : param.items()) {
        EXPECT_TRUE(std::set<std::string>({"name", "type", "unit", "min", "max", "default", "values", "description"})
                        .count(item.key()))
            << item.key();
        EXPECT_FALSE(item.value().is_null()) << param.dump();
      }
      EXPECT_TRUE(param.contains("name") && param.contains("type") && param.contains("description")) << param.dump();
      EXPECT_TRUE(param["type"] == "number" || param["type"] == "enum" || param["type"] == "boolean") << param.dump();
      EXPECT_EQ(param.contains("values"), param["type"] == "enum") << param.dump();
    }
  }
}

TEST(MonitorParams, ForceMonitorDescriptionNamesUnitsRangesDefaults) {
  const json description = ForceMonitor::describe().to_json();
  const json& params = description["params"];
  const auto find = [&](const std::string& name) {
    for (const auto& param : params) {
      if (param["name"] == name) return param;
    }
    return json();
  };
  EXPECT_EQ(find("max_force_n")["unit"], "N");
  EXPECT_EQ(find("max_force_n")["min"], 0.0);
  EXPECT_EQ(find("dwell_s")["default"], 0.02);
  EXPECT_EQ(find("cutoff_hz")["unit"], "Hz");
  EXPECT_EQ(find("max_torque_nm")["unit"], "Nm");
  EXPECT_EQ(find("axis")["type"], "enum");
  EXPECT_EQ(find("axis")["default"], "norm");
  EXPECT_EQ(find("axis")["values"], json({"norm", "x", "y", "z"}));
  EXPECT_FALSE(find("axis").contains("min"));
  EXPECT_FALSE(find("axis").contains("unit"));
  EXPECT_EQ(find("relative")["default"], false);
  EXPECT_EQ(find("max_sample_age_s")["default"], 0.1);
  EXPECT_FALSE(TimerMonitor::describe().to_json()["params"][0].contains("default")) << "duration_s is required";
}

TEST(MonitorParams, LibraryDocumentListsEveryMonitor) {
  const json library = monitor_library_json();
  EXPECT_EQ(library["library_version"], 1);
  ASSERT_EQ(library["skills"].size(), 3u);
  EXPECT_EQ(library["skills"][0]["name"], "ForceMonitor");
  EXPECT_EQ(library["skills"][2]["name"], "YankMonitor");
  EXPECT_EQ(make_monitor("CrystalBallMonitor"), nullptr);
}

TEST(MonitorParams, DefaultsAreApplied) {
  YankMonitor monitor;
  const ParamCheck check = monitor.reset(json{{"max_yank_n_per_s", 400}}, kT0);
  EXPECT_TRUE(check.ok()) << check.message();
  EXPECT_TRUE(monitor.armed());
  // Defaults: max_sample_age_s 0.1 s, so staleness is due 100 ms (+1 ns) after the start.
  EXPECT_EQ(monitor.next_deadline(), kT0 + std::chrono::milliseconds(100) + std::chrono::nanoseconds(1));
}

TEST(MonitorParams, RejectsAnUnknownParameter) {
  TimerMonitor timer;
  const ParamCheck check = timer.reset(json{{"duration_s", 1.0}, {"durration", 2}}, kT0);
  ASSERT_EQ(check.errors.size(), 1u);
  EXPECT_EQ(check.errors[0], "/durration: unknown parameter of TimerMonitor; expected one of duration_s");
}

TEST(MonitorParams, RejectsAMissingRequiredParameter) {
  TimerMonitor timer;
  expect_param_error(timer, json::object(), {"/duration_s: required, expected a number in [0.001, 86400] s"});
  YankMonitor yank;
  expect_param_error(yank, nullptr, {"/max_yank_n_per_s: required"});
}

TEST(MonitorParams, RejectsWrongTypesAndRanges) {
  TimerMonitor timer;
  expect_param_error(timer, json{{"duration_s", "10"}}, {"/duration_s: expected a number in [0.001, 86400] s", "got string \"10\""});
  expect_param_error(timer, json{{"duration_s", 0}}, {"/duration_s", "got number 0"});
  expect_param_error(timer, json{{"duration_s", 1e9}}, {"/duration_s"});
  ForceMonitor force;
  expect_param_error(force, json{{"max_force_n", 100}, {"axis", "w"}}, {"/axis: expected one of \"norm\", \"x\", \"y\", \"z\""});
  expect_param_error(force, json{{"max_force_n", 100}, {"relative", 1}}, {"/relative: expected true or false"});
  expect_param_error(force, json{{"max_force_n", -5}}, {"/max_force_n: expected a number in [0, 100000] N"});
  expect_param_error(force, json{{"max_force_n", 100}, {"cutoff_hz", 0}}, {"/cutoff_hz", "Hz"});
}

TEST(MonitorParams, RejectsParamsThatAreNotAnObject) {
  TimerMonitor timer;
  expect_param_error(timer, json::array({1}), {"(params): expected an object of parameters"});
}

TEST(MonitorParams, ForceMonitorNeedsALimit) {
  ForceMonitor force;
  expect_param_error(force, json::object(), {"/max_force_n: expected a force limit > 0 N or a torque limit"});
  EXPECT_TRUE(force.reset(json{{"max_torque_nm", 5}}, kT0).ok());
}

TEST(MonitorParams, ReportsEveryProblemAtOnce) {
  ForceMonitor force;
  const ParamCheck check = force.reset(json{{"max_force_n", "a"}, {"dwell_s", -1}, {"extra", true}}, kT0);
  EXPECT_EQ(check.errors.size(), 3u) << check.message();
  EXPECT_NE(check.message().find("; "), std::string::npos);
}

TEST(MonitorParams, AFailedResetDisarmsAnArmedMonitor) {
  TimerMonitor timer;
  ASSERT_TRUE(timer.reset(json{{"duration_s", 1}}, kT0).ok());
  ASSERT_TRUE(timer.armed());
  EXPECT_FALSE(timer.reset(json{{"duration_s", -1}}, kT0).ok());
  EXPECT_FALSE(timer.armed());
  EXPECT_FALSE(timer.next_deadline().has_value());
  EXPECT_EQ(timer.on_wrench(kT0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).code, kCodeNotArmed);
}

}  // namespace
}  // namespace rigger::monitor
