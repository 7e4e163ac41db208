// What cell_sim takes of a cell revision: moved objects become moves at their new world poses; a revision
// against another revision, a moved device, an added, removed or reshaped object are refused with the reason.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cell_revisions.hpp"
#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell_sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

cell_follower::FollowedRevision revision(std::uint64_t previous, json changes) {
  cell_follower::FollowedRevision r;
  r.revision = previous + 1;
  r.previous_revision = previous;
  r.cell = cell::load_cell_file(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
  r.changes = std::move(changes);
  return r;
}

TEST(PlanRevision, AMovedObjectIsMovedToItsWorldPoseInTheRevision) {
  const auto next = revision(
      4,
      json::parse(R"({"added":[],"removed":[],"moved":[{"id":"part","distance_m":0.1,"angle_deg":0}],"changed":[]})"));
  const RevisionPlan plan = plan_revision(next, 4);
  ASSERT_EQ(plan.refusal, "");
  ASSERT_EQ(plan.moves.size(), 1u);
  EXPECT_EQ(plan.moves[0].id, "part");
  EXPECT_TRUE(plan.moves[0].pose_world_object.isApprox(next.cell.pose_root_entity("part")));
}

TEST(PlanRevision, WhatThePhysicsDoesNotReadIsTakenWithoutMoves) {
  const RevisionPlan plan =
      plan_revision(revision(0, json::parse(R"({"changed":[{"id":"part","keys":["localized","comment"]}]})")), 0);
  EXPECT_EQ(plan.refusal, "");
  EXPECT_TRUE(plan.moves.empty());
}

TEST(PlanRevision, RefusesWhatNeedsTheModelBuiltAnewOrAnotherBase) {
  EXPECT_THAT(plan_revision(revision(3, json::object()), 2).refusal,
              AllOf(HasSubstr("changes revision 3, cell_sim runs on revision 2"), HasSubstr("restart")));
  EXPECT_THAT(plan_revision(revision(2, json::object()), 0).refusal, HasSubstr("cell_sim runs on its cell file"));
  EXPECT_THAT(plan_revision(revision(1, json::parse(R"({"added":["part_b"],"removed":["part"]})")), 1).refusal,
              HasSubstr("it adds or removes part_b, part: cell_sim builds its model at start"));
  EXPECT_THAT(plan_revision(revision(1, json::parse(R"({"changed":[{"id":"part","keys":["model"]}]})")), 1).refusal,
              HasSubstr("it changes model of part"));
  EXPECT_THAT(plan_revision(revision(1, json::parse(R"({"moved":[{"id":"robot"}]})")), 1).refusal,
              HasSubstr("it moves the device or frame robot"));
  EXPECT_THAT(plan_revision(revision(1, json::parse(R"({"moved":[{"id":"nothing"}]})")), 1).refusal,
              HasSubstr("it moves nothing, which it does not hold"));
  EXPECT_THAT(plan_revision(revision(1, json::parse(R"({"moved":[{"name":"part"}]})")), 1).refusal,
              HasSubstr("not the expected form"));
}

}  // namespace
}  // namespace rigger::cell_sim
