#pragma once
/// @file
/// One run of a skill on the SDK's fake devices, for a skill's unit tests: no DDS, no processes, time
/// advanced by the test (FakeTimers). Every device is present; `tweak` may remove some (to test a
/// skill's DEVICE_UNAVAILABLE) or replace them.
///
///   testing::RunHarness h(type, {{"goal", …}});
///   h.run->start();
///   h.robot.complete_move();          // the fake robot reports MOTION_SUCCEEDED
///   EXPECT_TRUE(h.succeeded()) << h.describe_result();

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigger/skill_sdk/testing/cell_fakes.hpp"
#include "rigger/skill_sdk/testing/fakes.hpp"

namespace rigger::skill_sdk::testing {

struct RunHarness {
  RunHarness(const SkillType& type, nlohmann::json params, const std::function<void(Devices&)>& tweak = nullptr) {
    Devices devices{&robot, &gripper, &resolver};
    devices.crane = &crane;
    devices.tracker = &tracker;
    devices.admittance = &admittance;
    devices.operator_panel = &operator_panel;
    devices.world_access = &world;
    if (tweak) tweak(devices);
    run = std::make_unique<SkillRun>(
        type, std::move(params), devices, timers, null_logger(),
        SkillRun::Callbacks{[this](double f, const std::string& m) { progress.emplace_back(f, m); },
                            [this](const SkillResult& r) {
                              ++results;
                              result = r;
                            }});
  }
  /// The skill's current state ("" before its parameters were checked and its features resolved).
  std::string state() const { return run->skill() ? run->skill()->state() : std::string(); }
  bool stopped() const { return result && result->kind == SkillResult::Kind::kStopped; }
  bool failed_with(const std::string& code) const {
    return result && result->kind == SkillResult::Kind::kFailure && result->code == code;
  }
  bool succeeded() const { return result && result->kind == SkillResult::Kind::kSuccess; }
  std::string describe_result() const {
    if (!result) return "no result";
    return std::string(to_string(result->kind)) + " " + result->code + ": " + result->message;
  }

  FakeTimers timers;
  FakeRobot robot;
  FakeGripper gripper;
  FakeResolver resolver;
  FakeCrane crane;
  FakeTracker tracker;
  FakeAdmittance admittance;
  FakeOperator operator_panel;
  FakeWorldAccess world;
  std::unique_ptr<SkillRun> run;
  std::vector<std::pair<double, std::string>> progress;
  std::optional<SkillResult> result;
  int results = 0;
};

}  // namespace rigger::skill_sdk::testing
