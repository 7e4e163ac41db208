// The parameter builder: what it declares is the ParamSpec written field by field, and what the
// registry refuses it refuses too.
#include <gtest/gtest.h>

#include "rigger/skill/skill_description.hpp"
#include "rigger/skill_sdk/params.hpp"
#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_sdk {
namespace {

TEST(ParamBuilder, DeclaresTheSameSpecAsTheFields) {
  const skill::ParamSpec built = params::number("max_force_n").unit("N").range(1, 500).fallback(80).doc("Largest force.");
  const skill::ParamSpec fields{"max_force_n", skill::ParamType::kNumber, "N", 1.0, 500.0, nlohmann::json(80), {},
                                "Largest force."};
  EXPECT_EQ(built, fields);
}

TEST(ParamBuilder, WithoutFallbackTheParameterIsRequired) {
  EXPECT_TRUE(params::pose("goal").spec().required());
  EXPECT_FALSE(params::speed_scale().spec().required());
  EXPECT_EQ(params::speed_scale(0.5).spec().default_value, nlohmann::json(0.5));
}

TEST(ParamBuilder, ChoiceKeepsItsValuesAndObjectIsAnObjectId) {
  const auto mode = params::choice("mode", {"once", "continuous"}).fallback("once").spec();
  EXPECT_EQ(mode.type, skill::ParamType::kEnum);
  EXPECT_EQ(mode.enum_values, (std::vector<std::string>{"once", "continuous"}));
  const auto object = params::object("object", "The load.", "load").spec();
  EXPECT_EQ(object.type, skill::ParamType::kObjectId);
  EXPECT_EQ(object.default_value, nlohmann::json("load"));
  EXPECT_TRUE(params::object("target", "The target.").spec().required());
}

TEST(ParamBuilder, ANumberListHasAUnitAndBoundsEachValue) {
  const auto torques = params::number_list("torques_nm").unit("Nm").range(0, 400).fallback(nlohmann::json::array()).spec();
  EXPECT_EQ(torques.type, skill::ParamType::kNumberList);
  EXPECT_EQ(torques.unit, "Nm");
  EXPECT_TRUE(skill::check_value(torques, {60, 400}, "/p", nullptr).empty());
  const auto errors = skill::check_value(torques, {60, 401}, "/p", nullptr);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/p/1");
}

TEST(ParamBuilder, SharedTimeoutHasOneRangeAndUnit) {
  const auto a = params::timeout_s(30).spec();
  const auto b = params::timeout_s(5, "The motion is stopped when it takes longer.").spec();
  EXPECT_EQ(a.unit, "s");
  EXPECT_EQ(a.min, b.min);
  EXPECT_EQ(a.max, b.max);
  EXPECT_NE(a.description, b.description);
}

TEST(ParamBuilder, AnIncoherentDeclarationIsRefusedWhenTheSkillIsRegistered) {
  skill::SkillDescription d;
  d.name = "Broken";
  d.kind = skill::SkillKind::kSkill;
  d.description = "A skill whose default lies outside its range.";
  d.params = {params::number("speed_scale").range(0.01, 1.0).fallback(2.0)};
  SkillRegistry registry;
  try {
    registry.add({d, [] { return std::unique_ptr<Skill>(); }});
    FAIL() << "an out-of-range default was registered";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/skills/Broken/params"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigger::skill_sdk
