// Operator decisions: prompt ids round-trip and anything else is refused; answers must be an option.

#include "operator_decisions.hpp"

#include <gtest/gtest.h>

namespace rigger::task_controller {
namespace {

TEST(PromptId, RoundTrips) {
  const PromptId id{"lift-1", "root/2/0", 3};
  EXPECT_EQ(id.str(), "lift-1#root/2/0#3");
  const auto parsed = PromptId::parse(id.str());
  ASSERT_TRUE(parsed);
  EXPECT_EQ(*parsed, id);
  const auto max = PromptId::parse("t#root#4294967295");
  ASSERT_TRUE(max);
  EXPECT_EQ(max->activation, 4294967295U);
}

TEST(PromptId, RefusesWhatIsNotOneOfOurs) {
  for (const char* text : {"", "#", "##", "screw-hole-3", "t#root", "t#root#", "#root#1", "t##1", "t#root#x",
                           "t#root#1x", "t#root#-1", "t#root#4294967296", "t#root#12345678901", "t#root# 1"}) {
    EXPECT_FALSE(PromptId::parse(text)) << '"' << text << '"';
  }
  EXPECT_FALSE(PromptId::parse(std::string(PromptId::kMaxLength, 'a') + "#root#1")) << "too long";
}

TEST(PromptId, SplitsAtTheLastTwoHashes) {
  // Task ids cannot hold '#' (the recipe schema), node ids never do; a text with more parts is split
  // from the right so that the activation and node are always the controller's own.
  const auto id = PromptId::parse("a#b#root/1#2");
  ASSERT_TRUE(id);
  EXPECT_EQ(id->task_id, "a#b");
  EXPECT_EQ(id->node_id, "root/1");
  EXPECT_EQ(id->activation, 2U);
}

TEST(OperatorOptions, AnAnswerMustBeAnOptionExactly) {
  const std::vector<std::string> options = {"crane", "joystick"};
  EXPECT_EQ(option_index(options, "crane"), 0U);
  EXPECT_EQ(option_index(options, "joystick"), 1U);
  EXPECT_FALSE(option_index(options, "Crane"));
  EXPECT_FALSE(option_index(options, ""));
  EXPECT_FALSE(option_index({}, "crane"));
  EXPECT_EQ(quoted_options(options), "\"crane\", \"joystick\"");
  EXPECT_EQ(quoted_options({}), "");
}

}  // namespace
}  // namespace rigger::task_controller
