#include "scripted_settings.hpp"

#include <gtest/gtest.h>

namespace rigger::scripted {
namespace {

const std::string kLibrary = std::string(RIGGER_SOURCE_DIR) + "/test/data/scripted_skill_library.json";

ScriptedExecutorSettings read(const std::string& keys) {
  const std::string json = R"({"library_file": ")" + kLibrary + "\"" + (keys.empty() ? "" : ", " + keys) + "}";
  return read_settings(Config::parse(json, "exec.json"), scripted_executor_settings());
}

std::string error_of(const std::string& keys) {
  try {
    read(keys);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ScriptedExecutorSettings, DefaultsAnnounceTheWholeLibrary) {
  const ScriptedExecutorSettings s = read("");
  EXPECT_GT(s.library["skills"].size(), 3u);
  EXPECT_TRUE(s.is_monitor.at("TimerMonitor"));
  EXPECT_FALSE(s.is_monitor.at("Pick"));
  EXPECT_EQ(s.default_skill.mode, Mode::kSucceed);
  EXPECT_EQ(s.default_monitor.mode, Mode::kRun);
  EXPECT_TRUE(s.by_skill.empty());
  EXPECT_TRUE(s.receipt_trace_path.empty());
}

TEST(ScriptedExecutorSettings, ReadsSkillsAndBehaviours) {
  const ScriptedExecutorSettings s = read(R"("skills": ["Pick", "TimerMonitor"], "default": {"delay_s": 0.5},
              "behaviours": {"Pick": {"mode": "fail"}, "TimerMonitor": {"stop_delay_s": 1}},
              "nodes": {"root/0": {"mode": "hang"}}, "receipt_trace_path": "/tmp/r.tsv")");
  EXPECT_EQ(s.library["skills"].size(), 2u);
  EXPECT_EQ(s.by_skill.at("Pick").mode, Mode::kFail);
  EXPECT_DOUBLE_EQ(s.by_skill.at("Pick").delay_s, 0.5);       // over the default
  EXPECT_EQ(s.by_skill.at("TimerMonitor").mode, Mode::kRun);  // over the monitors' default
  EXPECT_EQ(s.by_node.at("root/0").mode, Mode::kHang);
  EXPECT_EQ(s.receipt_trace_path, "/tmp/r.tsv");
}

TEST(ScriptedExecutorSettings, ErrorsNameTheKeyAndTheFile) {
  const std::string range = error_of(R"("default": {"delay_s": 4000})");
  EXPECT_NE(range.find("exec.json"), std::string::npos) << range;
  EXPECT_NE(range.find("/default/delay_s"), std::string::npos) << range;
  const std::string unknown = error_of(R"("behaviour": {})");
  EXPECT_NE(unknown.find("exec.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("/behaviour"), std::string::npos) << unknown;
  EXPECT_NE(error_of(R"("skills": ["Pick"], "behaviours": {"Place": {}})").find("/behaviours/Place"),
            std::string::npos);
  EXPECT_NE(error_of(R"("skills": ["Fly"])").find("not in the library: Fly"), std::string::npos);
}

}  // namespace
}  // namespace rigger::scripted
