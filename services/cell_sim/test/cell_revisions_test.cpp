// What cell_sim takes of a cell revision: moved objects become moves at their new world poses; a moved
// device, an added, removed or reshaped object are refused with the reason. The changes are cell_sim's own
// diff against the cell it runs on, whichever revision that is.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "cell_revisions.hpp"
#include "rigger/cell_config/cell_diff.hpp"
#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell_sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

const std::string kShipped = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";

cell::CellFile shipped() { return cell::load_cell_file(kShipped); }

RevisionPlan plan(const json& changes) { return plan_revision(changes, shipped()); }

TEST(PlanRevision, AMovedObjectIsMovedToItsWorldPoseInTheRevision) {
  // The running cell is the shipped one with `part` elsewhere (e.g. cell_sim restarted on an older file).
  std::ifstream in(kShipped, std::ios::binary);
  const json next_doc = json::parse(in);
  json running_doc = next_doc;
  for (json& entity : running_doc["entities"]) {
    if (entity["id"] == "part") entity["pose"]["position_m"][0] = entity["pose"]["position_m"][0].get<double>() - 0.1;
  }
  const cell::CellFile running = cell::cell_file_from_json(running_doc, "running");
  const cell::CellFile next = shipped();
  const RevisionPlan p = plan_revision(cell::diff_cells(running, running_doc, next, next_doc), next);
  ASSERT_EQ(p.refusal, "");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].id, "part");
  EXPECT_TRUE(p.moves[0].pose_world_object.isApprox(next.pose_root_entity("part")));
}

TEST(PlanRevision, WhatThePhysicsDoesNotReadIsTakenWithoutMoves) {
  const RevisionPlan p = plan(json::parse(R"({"changed":[{"id":"part","keys":["localized","comment"]}]})"));
  EXPECT_EQ(p.refusal, "");
  EXPECT_TRUE(p.moves.empty());
}

TEST(PlanRevision, RefusesWhatNeedsTheModelBuiltAnewOrAnotherBase) {
  EXPECT_THAT(plan(json::parse(R"({"added":["part_b"],"removed":["part"]})")).refusal,
              HasSubstr("it adds or removes part_b, part: cell_sim builds its model at start"));
  EXPECT_THAT(plan(json::parse(R"({"changed":[{"id":"part","keys":["model"]}]})")).refusal,
              HasSubstr("it changes model of part"));
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"id":"robot"}]})")).refusal,
              HasSubstr("it moves the device or frame robot"));
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"id":"nothing"}]})")).refusal,
              HasSubstr("it moves nothing, which it does not hold"));
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"name":"part"}]})")).refusal,
              HasSubstr("not in the expected form"));
}

}  // namespace
}  // namespace rigger::cell_sim
