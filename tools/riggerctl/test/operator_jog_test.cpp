// Pure helpers of `riggerctl operator` and `riggerctl jog`: prompt rendering, answer input, the key →
// twist mapping, joystick axes and the --script language.
#include <cmath>

#include <gtest/gtest.h>

#include "jog_input.hpp"
#include "operator_format.hpp"

namespace rigger::ctl {
namespace {

using jog::Key;
using jog::Twist;

TEST(OperatorFormat, ShowsTitleTextDetailsAndNumberedOptions) {
  PromptView p;
  p.prompt_id = "screw-h1";
  p.kind = "screw";
  p.task_id = "t1";
  p.title = "Screw hole h1";
  p.text = "Fit and tighten the screw, then confirm.";
  p.options = {"done", "failed", "abort"};
  p.details_json = R"({"hole": "h1", "screw_type": "M12x40", "torque_nm": 60})";
  const std::string s = format_prompt(p, 1, 2);
  EXPECT_NE(s.find("prompt 1 of 2: screw-h1"), std::string::npos) << s;
  EXPECT_NE(s.find("Screw hole h1"), std::string::npos) << s;
  EXPECT_NE(s.find("Fit and tighten"), std::string::npos) << s;
  EXPECT_NE(s.find("screw_type: M12x40"), std::string::npos) << s;
  EXPECT_NE(s.find("torque_nm: 60 N m"), std::string::npos) << s;
  EXPECT_NE(s.find("[1] done\n"), std::string::npos) << s;
  EXPECT_NE(s.find("[3] abort\n"), std::string::npos) << s;
}

TEST(OperatorFormat, ResolvesNumbersAndText) {
  const std::vector<std::string> options{"joystick", "visual servo", "Abort"};
  EXPECT_EQ(resolve_answer("1", options), "joystick");
  EXPECT_EQ(resolve_answer(" 3 ", options), "Abort");
  EXPECT_EQ(resolve_answer("visual servo", options), "visual servo");
  EXPECT_EQ(resolve_answer("abort", options), "Abort");
  EXPECT_FALSE(resolve_answer("0", options));
  EXPECT_FALSE(resolve_answer("4", options));
  EXPECT_FALSE(resolve_answer("", options));
  EXPECT_FALSE(resolve_answer("retry", options));
  // An option that reads like a number wins over the position.
  EXPECT_EQ(resolve_answer("2", {"2", "1"}), "2");
}

TEST(OperatorFormat, SplitsAssignments) {
  EXPECT_EQ(split_assignment("t#root/3#1=visual servo"),
            (std::pair<std::string, std::string>{"t#root/3#1", "visual servo"}));
  EXPECT_FALSE(split_assignment("noequals"));
  EXPECT_FALSE(split_assignment("=done"));
  EXPECT_FALSE(split_assignment("id="));
}

TEST(JogKeys, DecodesLettersArrowsAndPartialEscapes) {
  std::string bytes = "wAs d\x1b[A\x1b[D\x1b[C\x1b[Bq";
  const auto keys = jog::decode_keys(bytes);
  EXPECT_EQ(keys, (std::vector<Key>{Key::kXPlus, Key::kYPlus, Key::kXMinus, Key::kStop, Key::kYMinus, Key::kXPlus,
                                    Key::kYPlus, Key::kYMinus, Key::kXMinus, Key::kQuit}));
  EXPECT_TRUE(bytes.empty());
  bytes = "r\x1b[";  // an arrow split across two reads
  EXPECT_EQ(jog::decode_keys(bytes), std::vector<Key>{Key::kZPlus});
  EXPECT_EQ(bytes, "\x1b[");
  bytes += "A";
  EXPECT_EQ(jog::decode_keys(bytes), std::vector<Key>{Key::kXPlus});
  bytes = "F\x03x";
  EXPECT_EQ(jog::decode_keys(bytes), (std::vector<Key>{Key::kZMinus, Key::kQuit, Key::kOther}));
}

TEST(JogKeys, KeyToTwist) {
  EXPECT_EQ(jog::key_twist(Key::kXPlus, 0.05), (Twist{0.05, 0, 0, 0, 0, 0}));
  EXPECT_EQ(jog::key_twist(Key::kXMinus, 0.05), (Twist{-0.05, 0, 0, 0, 0, 0}));
  EXPECT_EQ(jog::key_twist(Key::kYPlus, 0.1), (Twist{0, 0.1, 0, 0, 0, 0}));
  EXPECT_EQ(jog::key_twist(Key::kYMinus, 0.1), (Twist{0, -0.1, 0, 0, 0, 0}));
  EXPECT_EQ(jog::key_twist(Key::kZPlus, 0.02), (Twist{0, 0, 0.02, 0, 0, 0}));
  EXPECT_EQ(jog::key_twist(Key::kZMinus, 0.02), (Twist{0, 0, -0.02, 0, 0, 0}));
  for (Key k : {Key::kStop, Key::kQuit, Key::kOther}) EXPECT_EQ(jog::key_twist(k, 0.05), Twist{});
}

TEST(JogStick, AxesDeadbandAndMap) {
  EXPECT_DOUBLE_EQ(jog::normalise_axis(0, 0.1), 0.0);
  EXPECT_DOUBLE_EQ(jog::normalise_axis(3000, 0.1), 0.0);  // inside the deadband
  EXPECT_DOUBLE_EQ(jog::normalise_axis(32767, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(jog::normalise_axis(-32767, 0.1), -1.0);
  EXPECT_DOUBLE_EQ(jog::normalise_axis(-32768, 0.1), -1.0);
  EXPECT_NEAR(jog::normalise_axis(static_cast<std::int16_t>(32767 * 0.55), 0.1), 0.5, 1e-4);

  const auto map = jog::parse_axis_map("-1,-0,+4");
  EXPECT_EQ(map.index, (std::array<int, 3>{1, 0, 4}));
  EXPECT_EQ(map.sign, (std::array<double, 3>{-1, -1, 1}));
  EXPECT_THROW(jog::parse_axis_map("1,2"), std::invalid_argument);
  EXPECT_THROW(jog::parse_axis_map("1,2,x"), std::invalid_argument);
  EXPECT_THROW(jog::parse_axis_map("1,2,3,4"), std::invalid_argument);

  // Stick forward (axis 1 negative) → +x; missing axis 4 → z = 0.
  Twist t = jog::stick_twist({0.0, -1.0}, map, 0.05);
  EXPECT_DOUBLE_EQ(t[0], 0.05);
  EXPECT_DOUBLE_EQ(t[1], 0.0);
  EXPECT_DOUBLE_EQ(t[2], 0.0);
  // Diagonal: the norm stays within the speed.
  t = jog::stick_twist({-1.0, -1.0}, map, 0.05);
  EXPECT_NEAR(std::hypot(t[0], t[1]), 0.05, 1e-12);
  EXPECT_GT(t[1], 0.0);
}

TEST(JogScript, ParsesSteps) {
  const auto s = jog::parse_script("x+0.05:2s,y-0.02z+0.01:500ms,rz+0.1:1,stop:0.5s", 0.25, 0.5);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].twist, (Twist{0.05, 0, 0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(s[0].duration_s, 2.0);
  EXPECT_EQ(s[1].twist, (Twist{0, -0.02, 0.01, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(s[1].duration_s, 0.5);
  EXPECT_EQ(s[2].twist, (Twist{0, 0, 0, 0, 0, 0.1}));
  EXPECT_EQ(s[3].twist, Twist{});
  EXPECT_DOUBLE_EQ(s[3].duration_s, 0.5);
  EXPECT_EQ(jog::parse_script("x+0.05:1,stop", 0.25, 0.5).back().duration_s, 0.0);

  EXPECT_EQ(jog::script_twist_at(s, 0.0), s[0].twist);
  EXPECT_EQ(jog::script_twist_at(s, 1.99), s[0].twist);
  EXPECT_EQ(jog::script_twist_at(s, 2.0), s[1].twist);
  EXPECT_EQ(jog::script_twist_at(s, 3.9), s[3].twist);
  EXPECT_FALSE(jog::script_twist_at(s, 4.0));
}

TEST(JogScript, RefusesBadSteps) {
  for (const char* bad : {"x+0.05", "x0.05:1s", "w+0.05:1s", "x+abc:1s", "x+0.05:soon", "x+0.05:-1s", "x+0.3:1s",
                          "rz+2:1s", "x+0.2y+0.2:1s", ":1s", ""}) {
    EXPECT_THROW(jog::parse_script(bad, 0.25, 0.5), std::invalid_argument) << bad;
  }
  try {
    jog::parse_script("x+0.05:1s,x+0.3:1s", 0.25, 0.5);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("step 2"), std::string::npos) << e.what();
  }
}

TEST(JogScript, Describe) {
  EXPECT_EQ(jog::describe(Twist{}), "stop");
  EXPECT_EQ(jog::describe(Twist{0.05, -0.02, 0, 0, 0, 0}), "x+0.05 y-0.02");
}

}  // namespace
}  // namespace rigger::ctl
