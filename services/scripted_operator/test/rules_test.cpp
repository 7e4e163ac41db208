#include "rules.hpp"

#include <gtest/gtest.h>

namespace rigger::scripted_operator {
namespace {

Prompt screw(const std::string& hole, const std::string& details_extra = "") {
  Prompt p;
  p.prompt_id = "screw-" + hole;
  p.kind = "screw";
  p.options = {"done", "failed", "abort"};
  p.details_json = R"({"hole": ")" + hole + R"(", "screw_type": "M12x40", "torque_nm": 60)" + details_extra + "}";
  p.active = true;
  return p;
}

Prompt decision(std::vector<std::string> options) {
  Prompt p;
  p.prompt_id = "t#root/3#1";
  p.task_id = "t";
  p.node_id = "root/3";
  p.kind = "decision";
  p.title = "OperatorDecision";
  p.text = "Which way?";
  p.options = std::move(options);
  p.active = true;
  return p;
}

std::vector<Rule> rules_from(const std::string& json) {
  return read_settings(Config::parse(json, "test.json"), scripted_operator_settings()).rules;
}

TEST(Rules, FirstMatchWinsAndDetailsNarrow) {
  const auto rules = rules_from(R"({"rules": [
      {"kind": "screw", "match_details": {"hole": "h2"}, "answer": "failed", "delay_s": 0.5},
      {"kind": "screw", "answer": "done", "delay_s": 1.0},
      {"kind": "decision", "answer": "retry"}]})");
  ASSERT_EQ(rules.size(), 3u);
  const Rule* r = first_match(rules, screw("h2"));
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r, &rules[0]);
  EXPECT_EQ(choose_answer(*r, screw("h2")), "failed");
  EXPECT_DOUBLE_EQ(r->delay_s, 0.5);
  r = first_match(rules, screw("h1"));
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r, &rules[1]);
  EXPECT_EQ(choose_answer(*r, screw("h1")), "done");
  r = first_match(rules, decision({"retry", "abort"}));
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r, &rules[2]);
}

TEST(Rules, NoRuleForAnotherKind) {
  const auto rules = rules_from(R"({"rules": [{"kind": "screw", "answer": "done"}]})");
  Prompt p = decision({"a", "b"});
  EXPECT_EQ(first_match(rules, p), nullptr);
}

TEST(Rules, WildcardKindAndIds) {
  const auto rules = rules_from(R"({"rules": [
      {"kind": "decision", "node_id": "root/9", "answer": "b"},
      {"kind": "*", "task_id": "t", "answer": ["missing", "a"]}]})");
  const Prompt p = decision({"a", "b"});
  const Rule* r = first_match(rules, p);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r, &rules[1]);               // node root/9 does not match root/3
  EXPECT_EQ(choose_answer(*r, p), "a");  // the first answer the prompt offers
  Prompt other = p;
  other.task_id = "u";
  EXPECT_EQ(first_match(rules, other), nullptr);
}

TEST(Rules, OnlyARuleNamingItAnswersAResumePrompt) {
  Prompt p = decision({"continue", "abort"});
  p.kind = "resume";
  p.node_id = "resume";
  EXPECT_EQ(first_match(rules_from(R"({"rules": [{"kind": "*", "answer": "continue"}]})"), p), nullptr);
  const auto named = rules_from(R"({"rules": [{"kind": "resume", "answer": "continue"}]})");
  ASSERT_EQ(first_match(named, p), &named[0]);
}

TEST(Rules, AnswerNotOfferedIsNotChosen) {
  const auto rules = rules_from(R"({"rules": [{"kind": "decision", "answer": "retry"}]})");
  const Prompt p = decision({"joystick", "visual servo", "abort"});
  ASSERT_NE(first_match(rules, p), nullptr);
  EXPECT_FALSE(choose_answer(rules[0], p).has_value());
}

TEST(Rules, DetailValuesCompareAcrossTypes) {
  const auto rules = rules_from(R"({"rules": [{"kind": "screw", "match_details": {"torque_nm": "60"}, "answer": "done"},
                                              {"kind": "screw", "match_details": {"urgent": true}, "answer": "abort"}]})");
  EXPECT_EQ(first_match(rules, screw("h1")), &rules[0]);
  Prompt p = screw("h1");
  p.details_json = R"({"torque_nm": 80, "urgent": true})";
  EXPECT_EQ(first_match(rules, p), &rules[1]);
  p.details_json = "not json";
  EXPECT_EQ(first_match(rules, p), nullptr);
  p.details_json = "";
  EXPECT_EQ(first_match(rules, p), nullptr);
}

TEST(Rules, MissingDetailDoesNotMatch) {
  const auto rules = rules_from(
      R"({"rules": [{"kind": "screw", "match_details": {"hole": "h2", "side": "left"}, "answer": "done"}]})");
  EXPECT_EQ(first_match(rules, screw("h2")), nullptr);
  EXPECT_NE(first_match(rules, screw("h2", R"(, "side": "left")")), nullptr);
}

TEST(Rules, InvalidAnswerIsRefusedWithPointer) {
  try {
    rules_from(R"({"rules": [{"kind": "screw", "answer": "done"}, {"kind": "screw", "answer": "perhaps"}]})");
    FAIL() << "an answer a screw prompt never offers must be refused";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "test.json");
    EXPECT_EQ(e.pointer(), "/rules/1/answer");
    EXPECT_NE(std::string(e.what()).find("done, failed, abort"), std::string::npos) << e.what();
  }
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "confirm", "answer": "retry"}]})"), ConfigError);
  EXPECT_NO_THROW(
      rules_from(R"({"rules": [{"kind": "confirm", "answer": "done"}, {"kind": "decision", "answer": "x"}]})"));
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision"}]})"), ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision", "answer": ""}]})"), ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision", "answer": []}]})"), ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision", "answer": "a", "delay_s": -1}]})"), ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision", "answer": "a", "match_details": {"x": [1]}}]})"),
               ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": [{"kind": "decision", "answer": "a", "anwser": "b"}]})"), ConfigError);
  EXPECT_THROW(rules_from(R"({"rules": {"kind": "decision"}})"), ConfigError);
}

TEST(Rules, SettingsDefaultsAndErrorsNameTheKeyAndTheFile) {
  const ScriptedOperatorSettings s = read_settings(Config::parse("{}", "test.json"), scripted_operator_settings());
  EXPECT_TRUE(s.rules.empty());
  EXPECT_EQ(s.operator_id, "scripted");
  const auto error_of = [](const std::string& json) -> std::string {
    try {
      rules_from(json);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string range = error_of(R"({"rules": [{"answer": "a", "delay_s": 3601}]})");
  EXPECT_NE(range.find("test.json"), std::string::npos) << range;
  EXPECT_NE(range.find("/rules/0/delay_s"), std::string::npos) << range;
  const std::string unknown = error_of(R"({"operator": "x"})");
  EXPECT_NE(unknown.find("test.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("/operator"), std::string::npos) << unknown;
  EXPECT_NE(error_of(R"({"operator_id": ""})").find("/operator_id"), std::string::npos);
}

TEST(Rules, CommandLineForm) {
  Rule r = parse_rule_argument("screw:hole=h2:failed@0.5");
  EXPECT_EQ(r.kind, "screw");
  EXPECT_EQ(r.match_details, nlohmann::json({{"hole", "h2"}}));
  EXPECT_EQ(r.answers, std::vector<std::string>{"failed"});
  EXPECT_DOUBLE_EQ(r.delay_s, 0.5);
  EXPECT_TRUE(matches(r, screw("h2")));
  EXPECT_FALSE(matches(r, screw("h1")));

  r = parse_rule_argument("decision:retry|continue@1s");
  EXPECT_EQ(r.kind, "decision");
  EXPECT_EQ(r.answers, (std::vector<std::string>{"retry", "continue"}));
  EXPECT_DOUBLE_EQ(r.delay_s, 1.0);

  r = parse_rule_argument("*:hole=h1,torque_nm=60:done");
  EXPECT_TRUE(r.kind.empty());
  EXPECT_TRUE(matches(r, screw("h1")));
  EXPECT_DOUBLE_EQ(r.delay_s, 0.0);
}

TEST(Rules, CommandLineErrorsNameTheRule) {
  for (const char* bad : {"screw", "screw:maybe", "screw:done@soon", "screw:hole:done", "a:b:c:d", "screw:done@-2"}) {
    try {
      parse_rule_argument(bad);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.file(), std::string("--rule '") + bad + "'");
    }
  }
  try {
    parse_rule_argument("screw:maybe");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/answer");
  }
}

TEST(Rules, Describe) {
  EXPECT_EQ(describe(screw("h1")), "screw h1 M12x40 60 N m");
  EXPECT_EQ(describe(decision({"joystick", "abort"})), "decision 'Which way?' [joystick|abort]");
  Prompt p = screw("h3", R"(, "side": "left")");
  EXPECT_EQ(describe(p), "screw h3 M12x40 60 N m side=left");
}

}  // namespace
}  // namespace rigger::scripted_operator
