#include "rigger/skill/predicate.hpp"

#include <gtest/gtest.h>

namespace rigger::skill {
namespace {

TEST(Predicate, ParsesNameAndArguments) {
  const auto p = parse_predicate(" attached( robot , $object ) ");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "attached");
  EXPECT_EQ(p->args, (std::vector<std::string>{"robot", "$object"}));
  EXPECT_FALSE(p->negated);
  EXPECT_EQ(p->to_string(), "attached(robot,$object)");
  EXPECT_EQ(p->referenced_params(), std::vector<std::string>{"object"});
}

TEST(Predicate, ParsesNegationAndNullary) {
  const auto p = parse_predicate("!ready");
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->negated);
  EXPECT_EQ(p->to_string(), "!ready()");
  EXPECT_EQ(parse_predicate("ready()")->to_string(), "ready()");
}

TEST(Predicate, AtomsMayContainPathCharacters) {
  const auto p = parse_predicate("at(load/grasp_side, frame:world, 1.5, x-y)");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->args.size(), 4U);
}

TEST(Predicate, RejectsMalformedWithPosition) {
  for (const char* bad : {"", "(x)", "p(", "p(a,)", "p(a b)", "p(a) q", "p($)", "p($1x)", "1p(a)", "p(a;b)"}) {
    std::string why;
    EXPECT_FALSE(parse_predicate(bad, &why)) << bad;
    EXPECT_NE(why.find("expected"), std::string::npos) << bad << ": " << why;
    EXPECT_NE(why.find("character"), std::string::npos) << why;
  }
}

TEST(Predicate, GroundsParameterReferences) {
  const auto p = parse_predicate("inserted($object, $target, $depth, $on)");
  ASSERT_TRUE(p);
  const nlohmann::json params = {{"object", "load"}, {"target", "target"}, {"depth", 2}, {"on", true}};
  EXPECT_EQ(p->ground(params), "inserted(load,target,2,true)");
}

TEST(Predicate, GroundFailsForMissingOrCompositeParameters) {
  const auto p = parse_predicate("localized($object)");
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->ground(nlohmann::json::object()));
  EXPECT_FALSE(p->ground({{"object", nlohmann::json::array({"a"})}}));
  EXPECT_FALSE(p->ground(nullptr));
}

TEST(Predicate, GroundIgnoresNegation) {
  const auto p = parse_predicate("!attached(robot,$object)");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->ground({{"object", "load"}}), "attached(robot,load)");
}

}  // namespace
}  // namespace rigger::skill
