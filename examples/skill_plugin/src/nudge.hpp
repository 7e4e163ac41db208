#pragma once
// Nudge: moves the robot's tool by an offset from wherever it is, verifies that it got there, and by
// default moves it back. An example of a skill written outside rigger against its skill SDK.

#include <optional>

#include <Eigen/Geometry>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/skill_sdk/skill.hpp"

namespace example {

class NudgeSkill : public rigger::skill_sdk::Skill {
 public:
  static const rigger::skill::SkillDescription& describe();
  NudgeSkill();

 private:
  void read_start();
  void move(const Eigen::Isometry3d& goal, const char* then);
  void verify(const Eigen::Isometry3d& goal, const char* then);
  void stop_robot(const SafeStopDone& done);

  Eigen::Isometry3d start_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d nudged_ = Eigen::Isometry3d::Identity();
};

}  // namespace example
