#include "rigger/skill_executor/settings.hpp"

#include <algorithm>

#include <gtest/gtest.h>

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;

skill_sdk::ExecutorSettings read(const std::string& json) {
  return read_settings(Config::parse(json, "exec.json"), skill_executor_settings("robot-skills"));
}

std::string error_of(const std::string& json) {
  try {
    read(json);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(SkillExecutorSettings, DefaultsOfferEverySkillAndDevice) {
  const auto s = read("{}");
  EXPECT_EQ(s.executor_id, "robot-skills");
  EXPECT_NE(std::find(s.skills.begin(), s.skills.end(), "MoveTo"), s.skills.end());
  EXPECT_TRUE(s.robot && s.gripper && s.world_model && s.crane && s.tracker && s.admittance && s.operator_panel);
  EXPECT_EQ(s.resolve_frame, "world");
  EXPECT_EQ(s.resolve_timeout, 2s);
}

TEST(SkillExecutorSettings, ReadsEveryKey) {
  const auto s = read(R"({"executor_id": "x", "skills": ["MoveTo"], "robot": false, "operator": false,
                          "resolve_frame": "cell", "resolve_timeout_s": 0.5})");
  EXPECT_EQ(s.executor_id, "x");
  EXPECT_EQ(s.skills, std::vector<std::string>{"MoveTo"});
  EXPECT_FALSE(s.robot);
  EXPECT_FALSE(s.operator_panel);
  EXPECT_TRUE(s.gripper);
  EXPECT_EQ(s.resolve_frame, "cell");
  EXPECT_EQ(s.resolve_timeout, 500ms);
}

TEST(SkillExecutorSettings, ErrorsNameTheKeyAndTheFile) {
  const std::string range = error_of(R"({"resolve_timeout_s": 60})");
  EXPECT_NE(range.find("exec.json"), std::string::npos) << range;
  EXPECT_NE(range.find("/resolve_timeout_s"), std::string::npos) << range;
  const std::string unknown = error_of(R"({"gripers": false})");
  EXPECT_NE(unknown.find("exec.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("/gripers"), std::string::npos) << unknown;
  EXPECT_NE(error_of(R"({"skills": ["Fly"]})").find("unknown skill 'Fly'"), std::string::npos);
  EXPECT_NE(error_of(R"({"skills": []})").find("/skills"), std::string::npos);
}

}  // namespace
}  // namespace rigger::skill_executor
