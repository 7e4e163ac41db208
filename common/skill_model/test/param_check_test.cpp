#include "rigger/skill/param_check.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "rigger/skill/units.hpp"

namespace rigger::skill {
namespace {

using Json = nlohmann::json;

SkillDescription make_description() {
  return description_from_json(Json::parse(R"json({
    "name": "Demo", "kind": "skill",
    "params": [
      {"name": "object", "type": "string", "min": 1, "max": 8},
      {"name": "speed", "type": "number", "unit": "m/s", "min": 0.001, "max": 0.5, "default": 0.1},
      {"name": "repeats", "type": "integer", "min": 1, "max": 10, "default": 1},
      {"name": "careful", "type": "boolean", "default": false},
      {"name": "mode", "type": "enum", "values": ["joystick", "visual_servo"], "default": "joystick"},
      {"name": "goal", "type": "pose", "default": {"position_m": [0, 0, 1], "rpy_deg": [0, 0, 0]}},
      {"name": "grasp", "type": "feature_ref", "default": "load/grasp_side"},
      {"name": "holes", "type": "string_list", "min": 1, "max": 4, "default": ["target/h1"]},
      {"name": "timeout", "type": "number", "unit": "s", "default": 10}
    ]})json"));
}

bool has_error(const ParamCheckResult& r, const std::string& pointer, const std::string& fragment) {
  for (const auto& e : r.errors) {
    if (e.pointer == pointer && e.message.find(fragment) != std::string::npos) {
      return true;
    }
  }
  return false;
}

std::string dump(const ParamCheckResult& r) {
  std::string out;
  for (const auto& e : r.errors) {
    out += e.to_string() + "\n";
  }
  return out;
}

TEST(CheckParams, FillsDefaults) {
  const auto d = make_description();
  const auto r = check_params(d, {{"object", "load"}}, "/p");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.params["object"], "load");
  EXPECT_EQ(r.params["speed"], 0.1);
  EXPECT_EQ(r.params["repeats"], 1);
  EXPECT_EQ(r.params["careful"], false);
  EXPECT_EQ(r.params["mode"], "joystick");
  EXPECT_EQ(r.params["grasp"], "load/grasp_side");
  EXPECT_EQ(r.params["holes"], Json::array({"target/h1"}));
  EXPECT_EQ(r.params.size(), d.params.size());
}

TEST(CheckParams, MissingRequiredNamesParameterAndExpectation) {
  const auto r = check_params(make_description(), Json::object(), "/root/params");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_EQ(r.errors[0].pointer, "/root/params/object");
  EXPECT_NE(r.errors[0].message.find("missing required parameter"), std::string::npos);
  EXPECT_NE(r.errors[0].message.find("string of length in [1, 8]"), std::string::npos) << r.errors[0].message;
}

TEST(CheckParams, NullParamsMeansEmpty) {
  const auto r = check_params(make_description(), nullptr);
  EXPECT_EQ(r.errors.size(), 1U);
}

TEST(CheckParams, NonObjectParamsRejected) {
  const auto r = check_params(make_description(), Json::array(), "/x");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_EQ(r.errors[0].pointer, "/x");
}

TEST(CheckParams, UnknownParameterListsDeclaredOnes) {
  const auto r = check_params(make_description(), {{"object", "load"}, {"sped", 0.2}}, "/p");
  ASSERT_EQ(r.errors.size(), 1U) << dump(r);
  EXPECT_EQ(r.errors[0].pointer, "/p/sped");
  EXPECT_NE(r.errors[0].message.find("\"speed\""), std::string::npos);
}

TEST(CheckParams, ReportsEveryErrorNotOnlyTheFirst) {
  const Json params = {{"object", 3}, {"speed", 2.0}, {"repeats", 1.5}, {"careful", "yes"}, {"mode", "auto"},
                       {"grasp", "load"}, {"holes", Json::array()}, {"bogus", 1}};
  const auto r = check_params(make_description(), params, "/p");
  EXPECT_EQ(r.errors.size(), 8U) << dump(r);
  EXPECT_TRUE(has_error(r, "/p/object", "expected string"));
  EXPECT_TRUE(has_error(r, "/p/speed", "number in [0.001, 0.5] m/s, got 2 m/s"));
  EXPECT_TRUE(has_error(r, "/p/repeats", "expected integer in [1, 10]"));
  EXPECT_TRUE(has_error(r, "/p/careful", "expected boolean"));
  EXPECT_TRUE(has_error(r, "/p/mode", "one of \"joystick\", \"visual_servo\""));
  EXPECT_TRUE(has_error(r, "/p/grasp", "feature reference"));
  EXPECT_TRUE(has_error(r, "/p/holes", "got 0 items"));
  EXPECT_TRUE(has_error(r, "/p/bogus", "unknown parameter"));
}

TEST(CheckParams, RangeBoundsAreInclusive) {
  const auto d = make_description();
  EXPECT_TRUE(check_params(d, {{"object", "l"}, {"speed", 0.5}, {"repeats", 10}}).ok());
  EXPECT_TRUE(check_params(d, {{"object", "12345678"}, {"speed", 0.001}, {"repeats", 1}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "123456789"}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", ""}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "a"}, {"repeats", 0}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "a"}, {"repeats", 11}}).ok());
}

TEST(CheckParams, StringLengthCountsCodePoints) {
  // "äääääääá" is 8 code points but 16 bytes.
  EXPECT_TRUE(check_params(make_description(), {{"object", "\xC3\xA4\xC3\xA4\xC3\xA4\xC3\xA4\xC3\xA4\xC3\xA4\xC3\xA4\xC3\xA1"}}).ok());
}

TEST(CheckParams, QuantityConvertsToDeclaredSiUnit) {
  const auto d = make_description();
  const auto r = check_params(d, {{"object", "load"}, {"speed", {{"value", 200}, {"unit", "mm/s"}}},
                                  {"timeout", {{"value", 1500}, {"unit", "ms"}}}});
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_DOUBLE_EQ(r.params["speed"].get<double>(), 0.2);
  EXPECT_DOUBLE_EQ(r.params["timeout"].get<double>(), 1.5);
}

TEST(CheckParams, QuantityRangeCheckedAfterConversion) {
  const auto r = check_params(make_description(), {{"object", "load"}, {"speed", {{"value", 600}, {"unit", "mm/s"}}}}, "/p");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_NE(r.errors[0].message.find("got 0.6 m/s"), std::string::npos) << r.errors[0].message;
}

TEST(CheckParams, IncommensurableUnitRejected) {
  const auto r = check_params(make_description(), {{"object", "load"}, {"speed", {{"value", 1}, {"unit", "N"}}}}, "/p");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_EQ(r.errors[0].pointer, "/p/speed");
  EXPECT_NE(r.errors[0].message.find("cannot be converted to \"m/s\""), std::string::npos);
}

TEST(CheckParams, MalformedQuantityRejected) {
  const auto d = make_description();
  EXPECT_FALSE(check_params(d, {{"object", "l"}, {"speed", {{"value", 1}}}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "l"}, {"speed", {{"value", "1"}, {"unit", "m/s"}}}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "l"}, {"speed", {{"value", 0.1}, {"unit", "m/s"}, {"x", 1}}}}).ok());
}

TEST(CheckParams, IntegerRejectsFloatsAndQuantities) {
  const auto d = make_description();
  EXPECT_FALSE(check_params(d, {{"object", "l"}, {"repeats", 2.0}}).ok());
  EXPECT_FALSE(check_params(d, {{"object", "l"}, {"repeats", {{"value", 2}, {"unit", ""}}}}).ok());
}

TEST(CheckParams, PoseForms) {
  const auto d = make_description();
  auto with_goal = [&](const Json& goal) { return check_params(d, {{"object", "l"}, {"goal", goal}}, "/p"); };
  EXPECT_TRUE(with_goal({{"position_m", {1, 2, 3}}, {"rpy_deg", {0, 90, 0}}}).ok());
  EXPECT_TRUE(with_goal({{"position_m", {1, 2, 3}}, {"quaternion_xyzw", {0, 0, 0, 1}}, {"frame", "target"}}).ok());
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2}}, {"rpy_deg", {0, 0, 0}}}), "/p/goal/position_m", "3 numbers"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2, 3}}}), "/p/goal", "exactly one orientation"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2, 3}}, {"rpy_deg", {0, 0, 0}}, {"quaternion_xyzw", {0, 0, 0, 1}}}),
                        "/p/goal", "exactly one orientation"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2, 3}}, {"quaternion_xyzw", {0, 0, 0, 2}}}),
                        "/p/goal/quaternion_xyzw", "unit quaternion"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, "2", 3}}, {"rpy_deg", {0, 0, 0}}}), "/p/goal/position_m/1",
                        "finite number"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2, 3}}, {"rpy_deg", {0, 0, 0}}, {"scale", 1}}), "/p/goal/scale",
                        "unknown pose field"));
  EXPECT_TRUE(has_error(with_goal({{"position_m", {1, 2, 3}}, {"rpy_deg", {0, 0, 0}}, {"frame", ""}}), "/p/goal/frame",
                        "frame"));
  EXPECT_FALSE(with_goal("world").ok());
}

TEST(CheckParams, FeatureRefSyntax) {
  const auto d = make_description();
  for (const char* good : {"load/grasp_side", "target/screw_holes/h1", "a.b/c-d"}) {
    EXPECT_TRUE(check_params(d, {{"object", "l"}, {"grasp", good}}).ok()) << good;
  }
  for (const char* bad : {"load", "/load", "load/", "load//x", "lo ad/x", ""}) {
    EXPECT_FALSE(check_params(d, {{"object", "l"}, {"grasp", bad}}).ok()) << bad;
  }
}

TEST(CheckParams, StringListItemsMustBeStrings) {
  const auto r = check_params(make_description(), {{"object", "l"}, {"holes", {"a", 1}}}, "/p");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_EQ(r.errors[0].pointer, "/p/holes/1");
}

// number_list: each value a number (or a quantity) in the declared unit and range, at its own pointer.
TEST(CheckParams, NumberListChecksAndConvertsEachValue) {
  const auto d = description_from_json(Json::parse(R"json({
    "name": "Demo", "kind": "skill",
    "params": [{"name": "torques_nm", "type": "number_list", "unit": "Nm", "min": 0, "max": 400, "default": []}]})json"));
  EXPECT_EQ(describe_expectation(d.params[0]), "array of numbers, each a number in [0, 400] Nm");
  auto r = check_params(d, Json::object());
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.params["torques_nm"], Json::array());
  r = check_params(d, {{"torques_nm", {60, 45.5}}});
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.params["torques_nm"], Json({60, 45.5}));
  r = check_params(d, {{"torques_nm", {60, -1, "x"}}}, "/p");
  EXPECT_EQ(r.errors.size(), 2U) << dump(r);
  EXPECT_TRUE(has_error(r, "/p/torques_nm/1", "got -1 Nm")) << dump(r);
  EXPECT_TRUE(has_error(r, "/p/torques_nm/2", "got string")) << dump(r);
  r = check_params(d, {{"torques_nm", 60}}, "/p");
  EXPECT_TRUE(has_error(r, "/p/torques_nm", "expected array of numbers")) << dump(r);
  EXPECT_EQ(param_type_from_string("number_list"), ParamType::kNumberList);
}

TEST(CheckParams, PointerTokensEscaped) {
  const auto r = check_params(make_description(), {{"object", "l"}, {"a/b", 1}}, "/p");
  ASSERT_EQ(r.errors.size(), 1U);
  EXPECT_EQ(r.errors[0].pointer, "/p/a~1b");
}

TEST(Units, ConversionTable) {
  EXPECT_EQ(conversion_factor("s", "s"), 1.0);
  EXPECT_DOUBLE_EQ(*conversion_factor("deg", "rad"), 3.14159265358979323846 / 180.0);
  EXPECT_DOUBLE_EQ(*conversion_factor("kN", "N"), 1000.0);
  EXPECT_FALSE(conversion_factor("mm", "s"));
  EXPECT_FALSE(conversion_factor("furlong", "m"));
  EXPECT_FALSE(conversion_factor("mm", "mm"));
  EXPECT_TRUE(is_si_unit("N/s"));
  EXPECT_FALSE(is_si_unit("mm"));
}

}  // namespace
}  // namespace rigger::skill
