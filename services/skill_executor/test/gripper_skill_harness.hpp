#pragma once
// A SkillRun of a gripper skill (AttachRobotToLoad, Release, Pick, Place) on fakes: robot, gripper,
// world resolver and crane, recording progress and result. `tweak` may remove devices.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cell_fakes.hpp"
#include "fakes.hpp"

namespace rigger::skill_executor::testing {

struct GripperRunHarness {
  GripperRunHarness(const SkillType& type, nlohmann::json params,
                    const std::function<void(Devices&)>& tweak = nullptr) {
    Devices devices{&robot, &gripper, &resolver};
    devices.crane = &crane;
    if (tweak) tweak(devices);
    run = std::make_unique<SkillRun>(
        type, std::move(params), devices, timers, null_logger(),
        SkillRun::Callbacks{[this](double f, const std::string& m) { progress.emplace_back(f, m); },
                            [this](const SkillResult& r) {
                              ++results;
                              result = r;
                            }});
  }
  const std::string& state() const { return run->skill()->state(); }
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
  std::unique_ptr<SkillRun> run;
  std::vector<std::pair<double, std::string>> progress;
  std::optional<SkillResult> result;
  int results = 0;
};

/// A tool pose in the robot base frame: position (m), tool z along +x of the base (as grasp_side).
inline Eigen::Isometry3d tool_facing_x(double x, double y, double z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

/// A tool pose in the robot base frame with the tool z pointing down (a pick from above).
inline Eigen::Isometry3d tool_down(double x, double y, double z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

}  // namespace rigger::skill_executor::testing
