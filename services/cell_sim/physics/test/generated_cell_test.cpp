// A cell the repository does not ship, described only by a cell file and STEP models written here with
// OpenCascade: a fixture table, an L-shaped 25 kg bracket on the crane's rope (two solids), a flange plate
// with six holes as the static target, and three loose parts on the table. The physics builds it, and what
// it builds behaves: parts settle on the table, the bracket hangs from the rope. Bad objects are refused
// with the file, the JSON pointer and what was expected.
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Pln.hxx>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "rigger/cad/model.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using json = nlohmann::json;

constexpr double kTableTopZ = 0.70;

TopoDS_Shape box(const gp_Pnt& low, const gp_Pnt& high) { return BRepPrimAPI_MakeBox(low, high).Shape(); }

// The L bracket: a base plate 0.40 x 0.30 x 0.03 m and a web 0.03 x 0.30 x 0.30 m standing on its -x edge,
// as two solids (each convex: MuJoCo collides one convex hull per solid).
TopoDS_Shape l_bracket() {
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  builder.Add(compound, box({-0.20, -0.15, 0.0}, {0.20, 0.15, 0.03}));
  builder.Add(compound, box({-0.20, -0.15, 0.03}, {-0.17, 0.15, 0.33}));
  return compound;
}

// The flange plate: 0.50 m across, 0.04 m thick, frame at the centre of its top face, six 22 mm through
// holes on a 0.36 m bolt circle.
TopoDS_Shape flange_plate() {
  const TopoDS_Shape disc = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -0.04), gp::DZ()), 0.25, 0.04).Shape();
  TopTools_ListOfShape arguments, tools;
  arguments.Append(disc);
  for (int k = 0; k < 6; ++k) {
    const double angle = k * M_PI / 3.0;
    tools.Append(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.18 * std::cos(angle), 0.18 * std::sin(angle), -0.05), gp::DZ()),
                                          0.011, 0.06)
                     .Shape());
  }
  BRepAlgoAPI_Cut cut;
  cut.SetArguments(arguments);
  cut.SetTools(tools);
  cut.Build();
  EXPECT_TRUE(cut.IsDone());
  return cut.Shape();
}

json pose(double x, double y, double z) { return {{"position_m", {x, y, z}}, {"rpy_deg", {0, 0, 0}}}; }

// A folder with the cell file (the shared cell's devices, these objects) and its models/.
class GeneratedCell {
 public:
  GeneratedCell() {
    char name[] = "/tmp/rigger_generated_cell_XXXXXX";
    dir_ = ::mkdtemp(name);
    std::filesystem::create_directories(dir_ / "models");
    cad::write_step(box({-0.6, -0.4, -kTableTopZ}, {0.6, 0.4, 0.0}), "table", dir_ / "models/table.step");
    cad::write_step(l_bracket(), "bracket", dir_ / "models/bracket.step");
    cad::write_step(flange_plate(), "flange", dir_ / "models/flange.step");
    cad::write_step(box({-0.05, -0.04, -0.03}, {0.05, 0.04, 0.03}), "block", dir_ / "models/block.step");
    cad::write_step(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -0.05), gp::DZ()), 0.04, 0.10).Shape(), "roller",
                    dir_ / "models/roller.step");

    std::ifstream shared(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
    cell_ = json::parse(shared);
    json devices = json::array();
    for (const json& entity : cell_["entities"]) {
      if (entity["kind"] != "object") devices.push_back(entity);
    }
    cell_["entities"] = devices;
    const auto object = [&](const std::string& id, json where, json model) {
      cell_["entities"].push_back({{"id", id}, {"kind", "object"}, {"parent", "world"}, {"pose", where}, {"model", model}});
      return cell_["entities"].size() - 1;
    };
    object("fixture_table", pose(5.5, 1.0, kTableTopZ), {{"static", true}, {"step", "models/table.step"}});
    const std::size_t bracket = object("bracket", pose(4.5, 3.5, 2.0), {{"mass_kg", 25.0}, {"step", "models/bracket.step"}});
    cell_["entities"][bracket]["features"] = {
        {"rope_attachment", pose(-0.08, 0.0, 0.35)},
        {"grasp_frames", {{{"id", "grasp_web"}, {"pose", {{"position_m", {-0.20, 0.0, 0.18}}, {"rpy_deg", {0, 90, 0}}}}}}},
        {"insertion", {{"target", "flange"}, {"pose_in_target", pose(0.0, 0.0, 0.0)}}}};
    object("flange", pose(4.5, 3.5, 0.04), {{"static", true}, {"step", "models/flange.step"}});
    // Dropped from 2 mm above the table top.
    object("part_a", pose(5.2, 0.8, kTableTopZ + 0.032), {{"mass_kg", 2.0}, {"step", "models/block.step"}});
    object("part_b", pose(5.5, 1.1, kTableTopZ + 0.052), {{"density_kg_m3", 7850.0}, {"step", "models/roller.step"}});
    object("part_c", pose(5.8, 0.8, kTableTopZ + 0.042),
           {{"shape", "box"}, {"size_m", {0.12, 0.10, 0.08}}, {"mass_kg", 1.5}});
  }
  ~GeneratedCell() { std::filesystem::remove_all(dir_); }

  json& document() { return cell_; }
  std::filesystem::path dir() const { return dir_; }
  /// The entity index of `id` in the cell file.
  std::size_t index_of(const std::string& id) const {
    for (std::size_t i = 0; i < cell_["entities"].size(); ++i) {
      if (cell_["entities"][i]["id"] == id) return i;
    }
    ADD_FAILURE() << "no entity " << id;
    return 0;
  }
  CellGeometry load() const {
    const std::filesystem::path path = dir_ / "cell.json";
    std::ofstream(path) << cell_.dump(2);
    return load_cell_geometry(path);
  }
  std::string error() const {
    try {
      load();
    } catch (const CellGeometryError& error) {
      return error.what();
    }
    return "";
  }

 private:
  std::filesystem::path dir_;
  json cell_;
};

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
  EXPECT_GT(bracket.translation().z(), 1.5) << "held above the flange";
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
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
