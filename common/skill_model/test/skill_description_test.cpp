#include "rigger/skill/skill_description.hpp"

#include <gtest/gtest.h>

namespace rigger::skill {
namespace {

using Json = nlohmann::json;

Json pick_json() {
  return Json::parse(R"json({
    "name": "Pick", "kind": "skill", "description": "grasp an object",
    "params": [
      {"name": "object", "type": "string", "description": "world-model id"},
      {"name": "grasp", "type": "feature_ref"},
      {"name": "speed_m_per_s", "type": "number", "unit": "m/s", "min": 0.01, "max": 0.5, "default": 0.1}
    ],
    "resources": ["robot", "gripper", "$object"],
    "preconditions": ["localized($object)"],
    "postconditions": ["attached(robot,$object)", "!on_floor($object)"]
  })json");
}

bool has_error(const std::vector<ModelError>& errors, const std::string& pointer, const std::string& fragment) {
  for (const auto& e : errors) {
    if (e.pointer == pointer && e.message.find(fragment) != std::string::npos) {
      return true;
    }
  }
  return false;
}

std::string dump(const std::vector<ModelError>& errors) {
  std::string out;
  for (const auto& e : errors) {
    out += e.to_string() + "\n";
  }
  return out;
}

TEST(SkillDescription, ParsesFullDescription) {
  const auto d = description_from_json(pick_json());
  EXPECT_EQ(d.name, "Pick");
  EXPECT_EQ(d.kind, SkillKind::kSkill);
  ASSERT_EQ(d.params.size(), 3U);
  EXPECT_TRUE(d.params[0].required());
  EXPECT_FALSE(d.params[2].required());
  EXPECT_EQ(d.params[2].unit, "m/s");
  EXPECT_EQ(d.resources, (std::vector<std::string>{"robot", "gripper", "$object"}));
  ASSERT_EQ(d.postconditions.size(), 2U);
  EXPECT_TRUE(d.postconditions[1].negated);
  EXPECT_NE(d.find_param("grasp"), nullptr);
  EXPECT_EQ(d.find_param("nope"), nullptr);
}

TEST(SkillDescription, JsonRoundTripIsLossless) {
  const auto d = description_from_json(pick_json());
  const Json j = to_json(d);
  const auto again = description_from_json(j);
  EXPECT_EQ(again, d);
  EXPECT_EQ(to_json(again), j);
}

TEST(SkillDescription, RoundTripOfEveryParamType) {
  const auto d = description_from_json(Json::parse(R"json({
    "name": "All", "kind": "condition", "params": [
      {"name": "a", "type": "number", "unit": "N", "min": -1, "max": 1, "default": 0.5},
      {"name": "b", "type": "integer", "default": 3},
      {"name": "c", "type": "boolean", "default": true},
      {"name": "d", "type": "string", "max": 3},
      {"name": "e", "type": "enum", "values": ["x", "y"], "default": "y"},
      {"name": "f", "type": "pose"},
      {"name": "g", "type": "feature_ref"},
      {"name": "h", "type": "string_list", "default": []}],
    "postconditions": ["ok($e)"]})json"));
  EXPECT_EQ(description_from_json(to_json(d)), d);
}

TEST(SkillDescription, KindNames) {
  EXPECT_EQ(to_string(SkillKind::kMonitor), "monitor");
  EXPECT_EQ(skill_kind_from_string("condition"), SkillKind::kCondition);
  EXPECT_FALSE(skill_kind_from_string("Skill"));
}

TEST(SkillDescription, ReportsEveryErrorWithPointer) {
  Json j = pick_json();
  j["name"] = "pick";                               // not PascalCase
  j["kind"] = "action";                             // unknown kind
  j["params"][1]["type"] = "vector";                // unknown type
  j["params"][2]["unit"] = "mm/s";                  // not SI
  j["resources"].push_back("forklift");             // unknown resource
  j["preconditions"].push_back("!localized($object)");  // negated precondition
  j["postconditions"].push_back("moved($nope)");    // unknown parameter
  j["extra"] = 1;                                   // unknown key
  const auto parsed = parse_description(j, "/skills/0");
  EXPECT_FALSE(parsed.ok());
  const auto& e = parsed.errors;
  EXPECT_TRUE(has_error(e, "/skills/0/name", "PascalCase")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/kind", "expected \"skill\", \"monitor\" or \"condition\"")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/params/1/type", "expected one of")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/params/2/unit", "not an SI unit")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/resources/3", "\"forklift\"")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/preconditions/1", "cannot be negated")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/postconditions/2", "unknown parameter \"$nope\"")) << dump(e);
  EXPECT_TRUE(has_error(e, "/skills/0/extra", "unknown key")) << dump(e);
}

TEST(SkillDescription, DefaultMustSatisfyDeclaration) {
  Json j = pick_json();
  j["params"][2]["default"] = 0.9;
  const auto parsed = parse_description(j);
  ASSERT_FALSE(parsed.ok());
  EXPECT_TRUE(has_error(parsed.errors, "/params/2/default", "does not satisfy")) << dump(parsed.errors);
}

TEST(SkillDescription, ParamDeclarationCoherence) {
  auto errors_of = [](const Json& param) {
    Json j = {{"name", "X"}, {"kind", "skill"}, {"params", Json::array({param})}};
    return parse_description(j).errors;
  };
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "number"}, {"min", 2}, {"max", 1}}), "/params/0/max",
                        "max >= min"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "enum"}}), "/params/0", "non-empty array"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "enum"}, {"values", {"x", "x"}}}), "/params/0/values/1",
                        "duplicate"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "boolean"}, {"min", 0}}), "/params/0/min", "applies to"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "string"}, {"unit", "m"}}), "/params/0/unit",
                        "only number, integer and number_list"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "string"}, {"min", 1.5}}), "/params/0/min",
                        "non-negative integer"));
  EXPECT_TRUE(has_error(errors_of({{"name", "a"}, {"type", "string"}, {"values", {"x"}}}), "/params/0/values",
                        "enum parameters only"));
  EXPECT_TRUE(has_error(errors_of({{"name", "Bad"}, {"type", "string"}}), "/params/0/name", "snake_case"));
  EXPECT_TRUE(has_error(errors_of({{"type", "string"}}), "/params/0", "missing \"name\""));
  EXPECT_TRUE(has_error(errors_of("x"), "/params/0", "expected a parameter object"));
}

TEST(SkillDescription, DuplicateParamNames) {
  Json j = pick_json();
  j["params"].push_back({{"name", "object"}, {"type", "string"}});
  EXPECT_TRUE(has_error(parse_description(j).errors, "/params/3/name", "duplicate parameter"));
}

TEST(SkillDescription, MonitorsClaimNothingAndHaveNoPostconditions) {
  Json monitor = {{"name", "YankMonitor"}, {"kind", "monitor"}, {"params", Json::array()},
                  {"resources", {"robot"}}, {"postconditions", {"ok()"}}};
  const auto parsed = parse_description(monitor);
  EXPECT_TRUE(has_error(parsed.errors, "/resources", "claim no resources")) << dump(parsed.errors);
  EXPECT_TRUE(has_error(parsed.errors, "/postconditions", "never succeed")) << dump(parsed.errors);
  Json condition = {{"name", "Localized"}, {"kind", "condition"}, {"resources", {"camera"}}};
  EXPECT_TRUE(has_error(parse_description(condition).errors, "/resources", "claim no resources"));
}

// "pausable" is a skill's promise to hold its devices on PAUSE: absent means false, it round-trips, and
// a monitor (which must keep monitoring) or a wrong type is refused with where.
TEST(SkillDescription, PausableIsASkillsFlag) {
  Json j = pick_json();
  EXPECT_FALSE(description_from_json(j).pausable);
  EXPECT_FALSE(to_json(description_from_json(j)).contains("pausable"));
  j["pausable"] = true;
  const SkillDescription d = description_from_json(j);
  EXPECT_TRUE(d.pausable);
  EXPECT_EQ(description_from_json(to_json(d)), d);
  j["pausable"] = "yes";
  EXPECT_TRUE(has_error(parse_description(j).errors, "/pausable", "expected true or false"));
  Json monitor = {{"name", "YankMonitor"}, {"kind", "monitor"}, {"params", Json::array()}, {"pausable", true}};
  EXPECT_TRUE(has_error(parse_description(monitor).errors, "/pausable", "never paused"));
}

TEST(SkillDescription, ResourceReferenceMustNameWordParameter) {
  Json j = pick_json();
  j["resources"] = {"$speed_m_per_s"};
  EXPECT_TRUE(has_error(parse_description(j).errors, "/resources/0", "\"$speed_m_per_s\""));
  j["resources"] = {"robot", "robot"};
  EXPECT_TRUE(has_error(parse_description(j).errors, "/resources/1", "duplicate resource"));
}

TEST(SkillDescription, PredicateMayNotReferenceCompositeParameter) {
  Json j = {{"name", "Place"}, {"kind", "skill"},
            {"params", {{{"name", "goal"}, {"type", "pose"}}}},
            {"postconditions", {"at($goal)"}}};
  EXPECT_TRUE(has_error(parse_description(j).errors, "/postconditions/0", "scalar parameter"));
}

TEST(SkillDescription, NonObjectRejected) {
  EXPECT_THROW(description_from_json(Json::array()), SkillModelError);
  try {
    description_from_json({{"kind", "skill"}});
    FAIL() << "expected SkillModelError";
  } catch (const SkillModelError& e) {
    EXPECT_EQ(e.errors().size(), 1U);
    EXPECT_NE(std::string(e.what()).find("missing \"name\""), std::string::npos);
  }
}

TEST(SkillDescription, ResolveResourcesSubstitutesParameters) {
  const auto d = description_from_json(pick_json());
  EXPECT_EQ(resolve_resources(d, {{"object", "load"}}), (std::vector<std::string>{"robot", "gripper", "load"}));
  Json j = pick_json();
  j["resources"] = {"robot", "$grasp", "$object"};
  const auto d2 = description_from_json(j);
  // A feature reference claims its entity, and duplicates collapse.
  EXPECT_EQ(resolve_resources(d2, {{"object", "load"}, {"grasp", "load/grasp_side"}}),
            (std::vector<std::string>{"robot", "load"}));
}

}  // namespace
}  // namespace rigger::skill
