#include "behaviour.hpp"

#include <gtest/gtest.h>

namespace rigger::scripted {
namespace {

TEST(BehaviourTest, KeysOverrideTheFallback) {
  Behaviour fallback;
  fallback.mode = Mode::kRun;
  fallback.stop_delay_s = 2.0;
  auto cfg = Config::parse(R"({"mode": "fail", "code": "YANK_DETECTED", "delay_s": 0.5})", "test");
  const Behaviour b = parse_behaviour(cfg, fallback);
  cfg.finish();
  EXPECT_EQ(b.mode, Mode::kFail);
  EXPECT_EQ(b.code, "YANK_DETECTED");
  EXPECT_DOUBLE_EQ(b.delay_s, 0.5);
  EXPECT_DOUBLE_EQ(b.stop_delay_s, 2.0);  // from the fallback
}

TEST(BehaviourTest, EmptyObjectKeepsFallback) {
  Behaviour fallback;
  fallback.mode = Mode::kHang;
  const Behaviour b = parse_behaviour(Config::parse("{}", "test"), fallback);
  EXPECT_EQ(b.mode, Mode::kHang);
}

TEST(BehaviourTest, BadValuesNameTheKey) {
  const Behaviour fallback;
  for (const char* text : {R"({"mode": "explode"})", R"({"delay_s": -1})", R"({"code": ""})",
                           R"({"progress_steps": 5000})", R"({"never_stop": "yes"})"}) {
    try {
      parse_behaviour(Config::parse(text, "test"), fallback);
      ADD_FAILURE() << "accepted " << text;
    } catch (const ConfigError& e) {
      EXPECT_FALSE(e.pointer().empty()) << text;
    }
  }
}

}  // namespace
}  // namespace rigger::scripted
