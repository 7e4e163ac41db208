#pragma once
// What the built-in skills' tests do alike with a testing::RunHarness: drive a run along its success path
// to a state or to its end, shut it down in each state, and run every state's safe stop directly.
#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sdk_testing.hpp"

namespace rigger::skill_executor::run_steps {

/// Completes what the current state of the run waits for, as on the success path.
using Step = std::function<void(testing::RunHarness&)>;

/// Calls `step` until the run enters `target`; a fatal failure when it ends before, or is not there after
/// `max_steps` steps.
inline void drive_to(testing::RunHarness& h, const std::string& target, const Step& step, int max_steps = 20) {
  for (int i = 0; i < max_steps && !h.result && h.state() != target; ++i) {
    step(h);
    if (::testing::Test::HasFatalFailure()) return;
  }
  ASSERT_FALSE(h.result) << h.describe_result();
  ASSERT_EQ(h.state(), target);
}

/// Calls `step` until the run ends, at most `max_steps` times.
inline void run_to_end(testing::RunHarness& h, const Step& step, int max_steps = 20) {
  for (int i = 0; i < max_steps && !h.result; ++i) {
    step(h);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

/// For a skill that moves the robot and switches the magnet: a fresh run of `type` with `params` for each of
/// `states`, brought there by `start_and_drive(h, state)`, is shut down. A state in `moving` stops the robot
/// and is STOPPED only once the stop is confirmed; any other stops nothing. No safe stop switches the magnet,
/// and no wait of the left state stays pending.
inline void expect_shutdown_in_each_state(
    const SkillType& type, const nlohmann::json& params, const std::vector<std::string>& states,
    const std::vector<std::string>& moving,
    const std::function<void(testing::RunHarness&, const std::string&)>& start_and_drive) {
  using Kind = testing::FakeRobot::Op::Kind;
  for (const std::string& state : states) {
    SCOPED_TRACE(state);
    testing::RunHarness h(type, params);
    start_and_drive(h, state);
    if (::testing::Test::HasFatalFailure()) return;
    const auto commanded = h.gripper.commanded;
    h.run->shutdown("test");
    if (std::find(moving.begin(), moving.end(), state) != moving.end()) {
      EXPECT_EQ(h.robot.stops, 1);
      EXPECT_FALSE(h.result) << "STOPPED before the robot confirmed rest";
      ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
    } else {
      EXPECT_EQ(h.robot.stops, 0);
    }
    EXPECT_TRUE(h.stopped()) << h.describe_result();
    EXPECT_EQ(h.gripper.commanded, commanded) << "a safe stop switched the magnet";
    EXPECT_EQ(h.gripper.pending_waits(), 0u) << "a wait of the left state is still pending";
  }
}

/// Runs the safe stop of every state of the started run directly (also of the synchronous states the FSM
/// never rests in): each must report safe. `confirm` completes what a safe stop commanded and returns false
/// when it commanded nothing; a safe stop that commanded something must not report safe before that.
inline void expect_every_safe_stop_safe(testing::RunHarness& h, const std::function<bool()>& confirm = nullptr) {
  const Skill& skill = *h.run->skill();
  for (const auto& name : skill.state_names()) {
    std::optional<bool> safe;
    skill.find_state(name)->on_shutdown([&](bool s, const std::string&) { safe = s; });
    const bool reported = safe.has_value();
    if (confirm && confirm()) {
      EXPECT_FALSE(reported) << name << ": safe before its stop was confirmed";
    }
    ASSERT_TRUE(safe.has_value()) << name;
    EXPECT_TRUE(*safe) << name;
  }
}

/// For expect_every_safe_stop_safe(): confirms the robot's MOTION_STOP.
inline std::function<bool()> confirm_robot_stop(testing::RunHarness& h) {
  return [&h] { return h.robot.complete(testing::FakeRobot::Op::Kind::kStop, OpResult::success()); };
}

/// For expect_every_safe_stop_safe(): confirms an admittance command sent since the last call, which must be
/// OFF.
inline std::function<bool()> confirm_admittance_off(testing::RunHarness& h) {
  return [&h, seen = h.admittance.requests.size()]() mutable {
    if (h.admittance.requests.size() == seen) return false;
    seen = h.admittance.requests.size();
    EXPECT_EQ(h.admittance.requests.back().mode, AdmittanceModeRequest::kOff);
    return h.admittance.complete(OpResult::success());
  };
}

}  // namespace rigger::skill_executor::run_steps
