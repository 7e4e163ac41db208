#include "rigger/sim/generated_cell.hpp"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Compound.hxx>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "rigger/cad/model.hpp"

namespace rigger::sim {
namespace {

using json = nlohmann::json;

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
  if (!cut.IsDone()) throw std::runtime_error("generated cell: OpenCascade could not cut the flange's holes");
  return cut.Shape();
}

json pose(double x, double y, double z) { return {{"position_m", {x, y, z}}, {"rpy_deg", {0, 0, 0}}}; }

}  // namespace

GeneratedCell::GeneratedCell() : GeneratedCell(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json") {}

GeneratedCell::GeneratedCell(const std::filesystem::path& shared_cell_json) {
  char name[] = "/tmp/rigger_generated_cell_XXXXXX";
  if (::mkdtemp(name) == nullptr) throw std::runtime_error("generated cell: cannot make a folder under /tmp");
  dir_ = name;
  std::filesystem::create_directories(dir_ / "models");
  constexpr double kTop = kTableTopZ;
  cad::write_step(box({-0.6, -0.4, -kTop}, {0.6, 0.4, 0.0}), "table", dir_ / "models/table.step");
  cad::write_step(l_bracket(), "bracket", dir_ / "models/bracket.step");
  cad::write_step(flange_plate(), "flange", dir_ / "models/flange.step");
  cad::write_step(box({-0.05, -0.04, -0.03}, {0.05, 0.04, 0.03}), "block", dir_ / "models/block.step");
  cad::write_step(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -0.05), gp::DZ()), 0.04, 0.10).Shape(), "roller",
                  dir_ / "models/roller.step");

  std::ifstream shared(shared_cell_json);
  if (!shared) throw std::runtime_error("generated cell: cannot read " + shared_cell_json.string());
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
  object("fixture_table", pose(5.5, 1.0, kTop), {{"static", true}, {"step", "models/table.step"}});
  const std::size_t bracket = object("bracket", pose(4.5, 3.5, 2.0), {{"mass_kg", 25.0}, {"step", "models/bracket.step"}});
  cell_["entities"][bracket]["features"] = {
      {"rope_attachment", pose(-0.08, 0.0, 0.35)},
      {"grasp_frames", {{{"id", "grasp_web"}, {"pose", {{"position_m", {-0.20, 0.0, 0.18}}, {"rpy_deg", {0, 90, 0}}}}}}},
      {"insertion", {{"target", "flange"}, {"pose_in_target", pose(0.0, 0.0, 0.0)}}}};
  object("flange", pose(4.5, 3.5, 0.04), {{"static", true}, {"step", "models/flange.step"}});
  // Dropped from 2 mm above the table top.
  object("part_a", pose(5.2, 0.8, kTop + 0.032), {{"mass_kg", 2.0}, {"step", "models/block.step"}});
  object("part_b", pose(5.5, 1.1, kTop + 0.052), {{"density_kg_m3", 7850.0}, {"step", "models/roller.step"}});
  object("part_c", pose(5.8, 0.8, kTop + 0.042), {{"shape", "box"}, {"size_m", {0.12, 0.10, 0.08}}, {"mass_kg", 1.5}});
}

GeneratedCell::~GeneratedCell() {
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

std::size_t GeneratedCell::index_of(const std::string& id) const {
  for (std::size_t i = 0; i < cell_["entities"].size(); ++i) {
    if (cell_["entities"][i]["id"] == id) return i;
  }
  throw std::out_of_range("generated cell: no entity " + id);
}

std::filesystem::path GeneratedCell::write() const {
  const std::filesystem::path path = dir_ / "cell.json";
  std::ofstream(path) << cell_.dump(2);
  return path;
}

CellGeometry GeneratedCell::load() const { return load_cell_geometry(write()); }

std::string GeneratedCell::error() const {
  try {
    load();
  } catch (const CellGeometryError& error) {
    return error.what();
  }
  return "";
}

}  // namespace rigger::sim
