// What cell_sim takes of a cell revision: moved objects become moves at their new world poses; added, removed
// or reshaped objects and a moved static one have the model built anew; a moved camera is redrawn, not moved;
// any other moved or changed device and a removed or reshaped crane load are refused with the reason. The
// changes are cell_sim's own diff against the cell it runs on, whichever revision that is.
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

RevisionPlan plan(const json& changes) {
  return plan_revision(changes, shipped(), shipped());
}

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
  const RevisionPlan p = plan_revision(cell::diff_cells(running, running_doc, next, next_doc), running, next);
  ASSERT_EQ(p.refusal, "");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].id, "part");
  EXPECT_TRUE(p.moves[0].pose_world_object.isApprox(next.pose_root_entity("part")));
}

TEST(PlanRevision, WhatThePhysicsDoesNotReadIsTakenWithoutMoves) {
  const RevisionPlan p = plan(json::parse(R"({"changed":[{"id":"part","keys":["localized","comment"]}]})"));
  EXPECT_EQ(p.refusal, "");
  EXPECT_TRUE(p.moves.empty());
  EXPECT_FALSE(p.rebuild);
}

TEST(PlanRevision, AddedRemovedOrReshapedObjectsHaveTheModelBuiltAnew) {
  std::ifstream in(kShipped, std::ios::binary);
  json next_doc = json::parse(in);
  next_doc["entities"].push_back(json::parse(R"({"id": "part_b", "kind": "object", "parent": "world",
      "pose": {"position_m": [2.8, 1.4, 0.66], "rpy_deg": [0, 0, 0]},
      "model": {"shape": "box", "size_m": [0.1, 0.1, 0.1], "mass_kg": 1.0, "frame": "box centre"}})"));
  const RevisionPlan p = plan_revision(
      json::parse(R"({"added":["part_b"],"removed":["part"],"changed":[{"id":"target","keys":["model","comment"]}]})"),
      shipped(), cell::cell_file_from_json(next_doc, "next"));
  EXPECT_EQ(p.refusal, "");
  EXPECT_TRUE(p.rebuild);
  EXPECT_EQ(p.rebuild_reason, "adds part_b; removes part; changes model of target");
  EXPECT_TRUE(p.moves.empty());
}

TEST(PlanRevision, AMovedStaticObjectIsBuiltWhereItStandsAndAMovedFreeOneIsMovedAfter) {
  const RevisionPlan p = plan(json::parse(
      R"({"moved":[{"id":"part_fixture"},{"id":"part"}],"changed":[{"id":"part_fixture","keys":["model"]}]})"));
  EXPECT_EQ(p.refusal, "");
  EXPECT_TRUE(p.rebuild);
  EXPECT_EQ(p.rebuild_reason, "changes model of part_fixture; moves the static part_fixture");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].id, "part");
}

TEST(PlanRevision, RefusesWhatTouchesTheLoadOnTheRopeOrADevice) {
  EXPECT_THAT(plan(json::parse(R"({"changed":[{"id":"load","keys":["model"]}]})")).refusal,
              HasSubstr("it reshapes the crane's load load, which hangs from the rope"));
  EXPECT_THAT(plan(json::parse(R"({"added":["camera"]})")).refusal,
              HasSubstr("it adds the device or frame camera: cell_sim places devices at start"));
  EXPECT_THAT(plan(json::parse(R"({"removed":["nothing"]})")).refusal,
              HasSubstr("it removes the device or frame nothing"));
  EXPECT_THAT(plan(json::parse(R"({"changed":[{"id":"crane","keys":["camera"]}]})")).refusal,
              HasSubstr("it changes camera of the device or frame crane"));
  // A cell whose rope hooks another object.
  std::ifstream in(kShipped, std::ios::binary);
  json next_doc = json::parse(in);
  for (json& entity : next_doc["entities"]) {
    if (entity["id"] == "part")
      entity["features"]["rope_attachment"] = json::parse(R"({"position_m":[0,0,0.06],"rpy_deg":[0,0,0]})");
    if (entity["id"] == "load") entity["features"].erase("rope_attachment");
  }
  const cell::CellFile next = cell::cell_file_from_json(next_doc, "next");
  EXPECT_THAT(plan_revision(json::parse(R"({"changed":[{"id":"load","keys":["features"]}]})"), shipped(), next).refusal,
              HasSubstr("it takes the crane's load load off the rope for part"));
}

TEST(PlanRevision, RefusesAMovedDeviceAndWhatItCannotRead) {
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"id":"robot"}]})")).refusal,
              HasSubstr("it moves the device or frame robot"));
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"id":"nothing"}]})")).refusal,
              HasSubstr("it moves nothing, which it does not hold"));
  EXPECT_THAT(plan(json::parse(R"({"moved":[{"name":"part"}]})")).refusal,
              HasSubstr("not in the expected form"));
}

// A calibration draws the camera where it really is: the revision is taken, and nothing in the simulation moves
// (no object moves, no model built anew); the camera is only listed as redrawn. Any other device still is not moved.
TEST(PlanRevision, AMovedCameraIsADrawingCorrectedNotACameraMoved) {
  std::ifstream in(kShipped, std::ios::binary);
  const json running_doc = json::parse(in);
  json next_doc = running_doc;
  for (json& entity : next_doc["entities"]) {
    if (entity["id"] == "camera") {
      entity["pose"]["position_m"][1] = entity["pose"]["position_m"][1].get<double>() + 0.02;
      entity["pose"]["rpy_deg"][0] = entity["pose"]["rpy_deg"][0].get<double>() + 1.5;
    }
  }
  const cell::CellFile running = shipped();
  const cell::CellFile next = cell::cell_file_from_json(next_doc, "next");
  const json changes = cell::diff_cells(running, running_doc, next, next_doc);
  ASSERT_EQ(changes["moved"].size(), 1u);
  const RevisionPlan p = plan_revision(changes, running, next);
  EXPECT_EQ(p.refusal, "");
  EXPECT_EQ(p.cameras_redrawn, std::vector<std::string>{"camera"});
  EXPECT_TRUE(p.moves.empty());
  EXPECT_FALSE(p.rebuild);
  // A camera's intrinsics are still the device's own: a change of them asks for a restart.
  EXPECT_THAT(plan(json::parse(R"({"changed":[{"id":"camera","keys":["camera"]}]})")).refusal,
              HasSubstr("it changes camera of the device or frame camera"));
}

// The board is a geom of the gripper: a revision that mounts, changes or unmounts it (a changed key of the
// robot) builds the model anew; any other change of the robot still asks for a restart.
TEST(PlanRevision, ACalibrationBoardMountedOrUnmountedBuildsTheModelAnew) {
  std::ifstream in(kShipped, std::ios::binary);
  const json bare_doc = json::parse(in);
  json board_doc = bare_doc;
  std::ifstream board(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
  for (json& entity : board_doc["entities"])
    if (entity["id"] == "robot") entity["calibration_board"] = json::parse(board);
  const cell::CellFile bare = shipped();
  const cell::CellFile with_board = cell::cell_file_from_json(board_doc, "with the board");
  const json mounted = cell::diff_cells(bare, bare_doc, with_board, board_doc);
  EXPECT_EQ(mounted["changed"], json::parse(R"([{"id":"robot","keys":["calibration_board"]}])"));
  const RevisionPlan mount = plan_revision(mounted, bare, with_board);
  EXPECT_EQ(mount.refusal, "");
  EXPECT_TRUE(mount.rebuild);
  EXPECT_EQ(mount.rebuild_reason, "mounts the calibration board on robot");
  const RevisionPlan unmount =
      plan_revision(cell::diff_cells(with_board, board_doc, bare, bare_doc), with_board, bare);
  EXPECT_EQ(unmount.refusal, "");
  EXPECT_TRUE(unmount.rebuild);
  EXPECT_EQ(unmount.rebuild_reason, "unmounts the calibration board from robot");

  json other_doc = board_doc;
  for (json& entity : other_doc["entities"]) {
    if (entity["id"] != "robot") continue;
    entity["calibration_board"]["mount"]["position_m"][2] = 0.06;
    entity["pose"]["position_m"][0] = 2.56;
  }
  const cell::CellFile other = cell::cell_file_from_json(other_doc, "other");
  const RevisionPlan both = plan_revision(cell::diff_cells(with_board, board_doc, other, other_doc), with_board, other);
  EXPECT_THAT(both.refusal, HasSubstr("it moves the device or frame robot"));
}

}  // namespace
}  // namespace rigger::cell_sim
