// A cell the repository does not ship, described only by a cell file and STEP models written with
// OpenCascade: a fixture table, an L-shaped 25 kg bracket on the crane's rope (two solids), a flange plate
// with six holes as the static target, and three loose parts on the table. The physics builds it, and what
// it builds behaves: parts settle on the table, the bracket hangs from the rope. Bad objects are refused
// with the file, the JSON pointer and what was expected.
#include <BRepBuilderAPI_MakeFace.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Pln.hxx>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <string>

#include "rigger/cad/model.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/generated_cell.hpp"

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using json = nlohmann::json;

constexpr double kTableTopZ = GeneratedCell::kTableTopZ;

TEST(GeneratedCell, HasOneBodyPerObjectPartsSettleOnTheTableAndTheBracketHangs) {
  const GeneratedCell files;
  const CellGeometry cell = files.load();
  CellPhysics physics(cell);
  EXPECT_EQ(physics.object_bodies(),
            (std::vector<std::string>{"fixture_table", "bracket", "flange", "part_a", "part_b", "part_c"}));
  EXPECT_EQ(cell.load.id, "bracket");
  EXPECT_EQ(cell.target.id, "flange");
  // The roller's mass is its STEP volume times the density: pi r^2 h rho.
  EXPECT_NEAR(cell.objects[4].mass_kg, M_PI * 0.04 * 0.04 * 0.10 * 7850.0, 0.01);
  EXPECT_EQ(cell.objects[1].solids.size(), 2u) << "the L bracket is two convex solids";

  physics.step(2s);
  const std::vector<std::pair<std::string, double>> resting = {{"part_a", 0.03}, {"part_b", 0.05}, {"part_c", 0.04}};
  std::map<std::string, Eigen::Vector3d> settled;
  for (const auto& [id, half_height] : resting) {
    const Eigen::Vector3d position = physics.pose_world_object(id)->translation();
    settled[id] = position;
    // On the table, not through it (1 mm of contact penetration), not bounced off.
    EXPECT_NEAR(position.z(), kTableTopZ + half_height, 1.5e-3) << id;
    const auto start = std::find_if(cell.objects.begin(), cell.objects.end(),
                                    [&](const ObjectGeometry& object) { return object.id == id; });
    EXPECT_LT((position.head<2>() - start->pose_world_object.translation().head<2>()).norm(), 0.01) << id;
  }
  physics.step(1s);
  for (const auto& [id, half_height] : resting) {
    const Eigen::Vector3d position = physics.pose_world_object(id)->translation();
    std::cout << id << " rests " << 1e3 * (position.z() - kTableTopZ - half_height) << " mm from the table top, moved "
              << 1e3 * (position - settled[id]).norm() << " mm in the third second\n";
    EXPECT_LT((position - settled[id]).norm(), 2e-4) << id << " still moves";
    EXPECT_GT(physics.pose_world_object(id)->linear().col(2).z(), 0.9999) << id << " tipped over";
  }

  // The bracket hangs from the rope: the rope carries it and the hook block, the rope attachment is at the
  // hook, and the centre of mass (x = -0.079 m in the bracket frame) hangs below it.
  const CraneState crane = physics.crane_state();
  std::cout << "bracket: rope tension " << crane.rope_tension_n << " N, load cell " << crane.load_mass_estimate_kg
            << " kg, sway " << crane.sway_angle_rad.transpose() << " rad\n";
  EXPECT_NEAR(crane.rope_tension_n, 26.0 * 9.81, 0.02 * 26.0 * 9.81);
  EXPECT_NEAR(crane.load_mass_estimate_kg, 25.0, 0.5);
  const Eigen::Isometry3d bracket = physics.pose_world_load();
  const Eigen::Vector3d attachment_world = bracket * cell.load.pose_load_rope_attachment.translation();
  EXPECT_LT((attachment_world - crane.position_world_hook_m).norm(), 0.01);
  EXPECT_LT(std::abs(crane.sway_angle_rad.x()) + std::abs(crane.sway_angle_rad.y()), 0.01) << "hangs still";
  EXPECT_GT(bracket.translation().z(), cell.target.pose_world_target.translation().z() + 0.1) << "held above the flange";
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

// A cell revision that moves a loose part: the physics puts it there at rest, and it stays; the other
// parts do not move. What cannot be moved so is refused with the reason: the bracket on the rope, the
// static flange, an unknown object, a pose that is not one.
TEST(GeneratedCell, AMovedLoosePartStaysWhereItIsPutAndTheRestIsRefused) {
  const GeneratedCell files;
  CellPhysics physics(files.load());
  physics.step(1s);
  const Eigen::Isometry3d part_b = *physics.pose_world_object("part_b");
  Eigen::Isometry3d moved = *physics.pose_world_object("part_a");
  moved.translation() += Eigen::Vector3d(0.08, -0.12, 0.0);
  moved.rotate(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  const CommandResult result = physics.move_free_object("part_a", moved);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_LT((physics.pose_world_object("part_a")->translation() - moved.translation()).norm(), 1e-9);
  physics.step(1s);
  const Eigen::Isometry3d rests = *physics.pose_world_object("part_a");
  std::cout << "part_a 1 s after the move: " << 1e3 * (rests.translation() - moved.translation()).norm() << " mm, "
            << Eigen::AngleAxisd(rests.linear() * moved.linear().transpose()).angle() * 180.0 / M_PI << " deg\n";
  EXPECT_LT((rests.translation() - moved.translation()).norm(), 1e-3);
  EXPECT_LT(Eigen::AngleAxisd(rests.linear() * moved.linear().transpose()).angle(), 1e-3);
  EXPECT_LT((physics.pose_world_object("part_b")->translation() - part_b.translation()).norm(), 2e-4);

  const Eigen::Isometry3d bracket = physics.pose_world_load();
  const CommandResult on_rope = physics.move_free_object("bracket", moved);
  EXPECT_EQ(on_rope.status, CommandStatus::RejectedHeld);
  EXPECT_THAT(on_rope.message, HasSubstr("hangs from the crane's rope"));
  EXPECT_TRUE(physics.pose_world_load().isApprox(bracket));
  EXPECT_EQ(physics.move_free_object("flange", moved).status, CommandStatus::RejectedNotFree);
  EXPECT_EQ(physics.move_free_object("part_z", moved).status, CommandStatus::RejectedNotFree);
  const Eigen::Isometry3d before_bad = *physics.pose_world_object("part_a");
  Eigen::Isometry3d bad = moved;
  bad.translation().x() = NAN;
  EXPECT_EQ(physics.move_free_object("part_a", bad).status, CommandStatus::RejectedNonFinite);
  bad = moved;
  bad.linear() *= 2.0;
  EXPECT_EQ(physics.move_free_object("part_a", bad).status, CommandStatus::RejectedOutOfRange);
  EXPECT_TRUE(physics.pose_world_object("part_a")->isApprox(before_bad)) << "a refused move moved the part";
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

// The scenario's recipe for this cell: the demo's names replaced by the cell's, every hole of the flange
// screwed, and no name of the shipped cell's objects left.
TEST(GeneratedCell, TheScenariosRecipeNamesTheGeneratedCellsObjectsAndFeatures) {
  const GeneratedCell files;
  std::ifstream demo(std::string(RIGGER_SOURCE_DIR) + "/recipes/crane_insert.json");
  const json recipe = files.recipe(json::parse(demo), "generated-insert");
  const std::string text = recipe.dump();
  EXPECT_EQ(recipe["task_id"], "generated-insert");
  EXPECT_EQ(recipe["assumptions"], json::array({"hooked(crane,bracket)"}));
  for (const char* name : {"\"bracket/grasp_web\"", "\"bracket/pre_grasp\"", "\"object\":\"bracket\"",
                           "\"target\":\"flange\"", "\"flange/h6\""})
    EXPECT_NE(text.find(name), std::string::npos) << name << " missing from " << text;
  for (const char* name : {"\"load\"", "\"target\"", "\"load/", "\"target/"})
    EXPECT_EQ(text.find(std::string(":") + name), std::string::npos) << name << " left in " << text;
}

TEST(GeneratedCell, RefusesObjectsWithoutGeometryOrMass) {
  GeneratedCell files;
  const std::string part_a = "/entities/" + std::to_string(files.index_of("part_a"));
  json& model = files.document()["entities"][files.index_of("part_a")]["model"];
  model.erase("step");
  EXPECT_THAT(files.error(), AllOf(HasSubstr("cell.json: " + part_a + "/model: expected a geometry"),
                                   HasSubstr("got neither")));
  model["step"] = "models/block.step";
  model["mass_kg"] = 0.0;
  EXPECT_THAT(files.error(), HasSubstr(part_a + "/model/mass_kg: expected a number > 0"));
  model.erase("mass_kg");
  model["density_kg_m3"] = -7850.0;
  EXPECT_THAT(files.error(), HasSubstr(part_a + "/model/density_kg_m3: expected a number > 0"));
  model.erase("density_kg_m3");
  EXPECT_THAT(files.error(), HasSubstr(part_a + "/model/mass_kg: expected the mass of a free object"));
}

TEST(GeneratedCell, RefusesStepModelsThatAreEmptyOrNotClosedSolids) {
  GeneratedCell files;
  const std::string part_a = "/entities/" + std::to_string(files.index_of("part_a"));
  json& model = files.document()["entities"][files.index_of("part_a")]["model"];

  std::ofstream(files.dir() / "models/empty.step");
  model["step"] = "models/empty.step";
  EXPECT_THAT(files.error(), AllOf(HasSubstr(part_a + "/model/step: expected a STEP model of closed solids"),
                                   HasSubstr("empty.step")));

  // A single face: geometry, but no solid.
  cad::write_step(BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), -0.05, 0.05, -0.05, 0.05).Face(), "sheet",
                  files.dir() / "models/sheet.step");
  model["step"] = "models/sheet.step";
  EXPECT_THAT(files.error(), AllOf(HasSubstr(part_a + "/model/step: expected a STEP model of closed solids"),
                                   HasSubstr("no solid")));
}

}  // namespace
}  // namespace rigger::sim
