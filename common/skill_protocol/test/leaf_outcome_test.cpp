// A leaf's outcome through rigger/skill/event and back: the one conversion both endpoints use.

#include "rigger/skill_protocol/leaf_outcome.hpp"

#include <gtest/gtest.h>

namespace rigger::skill_protocol {
namespace {

LeafOutcome round_trip(const LeafOutcome& outcome) {
  rigger_skill_SkillEvent e{};
  to_wire(outcome, e);
  return from_wire(e);
}

TEST(LeafOutcome, EveryKindCodeAndMessageSurviveTheWire) {
  for (EventKind kind : {EventKind::kSuccess, EventKind::kFailure, EventKind::kStopped, EventKind::kProgress,
                         EventKind::kAccepted, EventKind::kPaused, EventKind::kResumed}) {
    const LeafOutcome out = round_trip({kind, "YANK_DETECTED", "yank 900 N/s", std::nullopt});
    EXPECT_EQ(out.kind, kind) << to_string(kind);
    EXPECT_EQ(out.code, "YANK_DETECTED");
    EXPECT_EQ(out.message, "yank 900 N/s");
    EXPECT_FALSE(out.progress) << to_string(kind);
  }
}

TEST(LeafOutcome, ProgressOnlyWhenKnownAndInRange) {
  const LeafOutcome half = round_trip({EventKind::kProgress, "", "", 0.5});
  ASSERT_TRUE(half.progress);
  EXPECT_DOUBLE_EQ(*half.progress, 0.5);
  rigger_skill_SkillEvent e{};
  e.kind = rigger_skill_SKILL_EVENT_PROGRESS;
  e.progress = 1.5;
  EXPECT_FALSE(from_wire(e).progress);
  e.progress = -1.0;
  EXPECT_FALSE(from_wire(e).progress);
  e.kind = rigger_skill_SKILL_EVENT_SUCCESS;
  e.progress = 0.5;
  EXPECT_FALSE(from_wire(e).progress) << "progress belongs to PROGRESS only";
}

TEST(LeafOutcome, UnknownProgressIsNegativeOnTheWireAndNullStringsReadEmpty) {
  rigger_skill_SkillEvent e{};
  to_wire({EventKind::kSuccess, "", "", std::nullopt}, e);
  EXPECT_LT(e.progress, 0.0);
  rigger_skill_SkillEvent empty{};
  empty.kind = rigger_skill_SKILL_EVENT_FAILURE;
  const LeafOutcome out = from_wire(empty);
  EXPECT_EQ(out.kind, EventKind::kFailure);
  EXPECT_EQ(out.code, "");
  EXPECT_EQ(out.message, "");
}

// The names the journal gives a leaf's answer to a PAUSE or RESUME, read back by riggerctl.
TEST(LeafOutcome, AnswerNamesSayWhetherTheLeafRefused) {
  EXPECT_STREQ(to_string(EventKind::kPaused), "PAUSED");
  EXPECT_EQ(answer_name(EventKind::kPaused, false), "PAUSED");
  EXPECT_EQ(answer_name(EventKind::kPaused, true), "NOT_PAUSED");
  EXPECT_EQ(answer_name(EventKind::kResumed, true), "NOT_RESUMED");
}

}  // namespace
}  // namespace rigger::skill_protocol
