#include "rigger/sim/generated_cell.hpp"

#include <stdlib.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Compound.hxx>

#include <array>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>

#include "rigger/cad/cad_json.hpp"
#include "rigger/cad/features.hpp"
#include "rigger/cad/model.hpp"

namespace rigger::sim {
namespace {

using json = nlohmann::json;

// The bolt circle of the flange's six holes and their radius, metres.
constexpr double kBoltCircleRadius = 0.18;
constexpr double kHoleRadius = 0.011;
// The inner face of the flange's marker lug (x in the flange's frame), 3 cm beyond the bracket's base plate.
constexpr double kLugInnerX = 0.23;

TopoDS_Shape box(const gp_Pnt& low, const gp_Pnt& high) {
  return BRepPrimAPI_MakeBox(low, high).Shape();
}

// The L bracket, frame at the centre of the base plate's bottom face: a base plate 0.40 x 0.30 x 0.03 m and
// a web 0.03 x 0.30 x 0.30 m standing on its -x edge, as two solids (each convex: MuJoCo collides one convex
// hull per solid).
TopoDS_Shape l_bracket() {
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  builder.Add(compound, box({-0.20, -0.15, 0.0}, {0.20, 0.15, 0.03}));
  builder.Add(compound, box({-0.20, -0.15, 0.03}, {-0.17, 0.15, 0.33}));
  return compound;
}

// `solid` with vertical through holes cut, each {x, y, radius} (metres), from z = `bottom` up for `height`.
TopoDS_Shape drilled(const TopoDS_Shape& solid, const std::vector<std::array<double, 3>>& holes, double bottom,
                     double height) {
  TopTools_ListOfShape arguments, tools;
  arguments.Append(solid);
  for (const auto& [x, y, radius] : holes)
    tools.Append(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, bottom), gp::DZ()), radius, height).Shape());
  BRepAlgoAPI_Cut cut;
  cut.SetArguments(arguments);
  cut.SetTools(tools);
  cut.Build();
  if (!cut.IsDone()) throw std::runtime_error("generated cell: OpenCascade could not cut the holes");
  return cut.Shape();
}

// The flange plate: 0.50 m across, 0.04 m thick, frame at the centre of its top face, six 22 mm through
// holes on a 0.36 m bolt circle; on its +x rim (the camera's side) a marker lug 0.02 x 0.24 x 0.12 m standing
// on the top face, as a second solid: the camera looks down at about 23 degrees, so markers on the top face
// were seen at 67 degrees from their normal, past the tracker's good viewing angle, and the tracker lost the
// flange during the insertion.
TopoDS_Shape flange_plate() {
  const TopoDS_Shape disc = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -0.04), gp::DZ()), 0.25, 0.04).Shape();
  std::vector<std::array<double, 3>> holes;
  for (int k = 0; k < 6; ++k) {
    const double angle = k * M_PI / 3.0;
    holes.push_back({kBoltCircleRadius * std::cos(angle), kBoltCircleRadius * std::sin(angle), kHoleRadius});
  }
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  builder.Add(compound, drilled(disc, holes, -0.05, 0.06));
  builder.Add(compound, box({kLugInnerX, -0.12, 0.0}, {kLugInnerX + 0.02, 0.12, 0.12}));
  return compound;
}

json pose(double x, double y, double z, double roll = 0, double pitch = 0, double yaw = 0) {
  return {{"position_m", {x, y, z}}, {"rpy_deg", {roll, pitch, yaw}}};
}

std::string text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

// A written model's faces and edges, as `riggerctl cad inspect` lists them: references are taken from the
// file the services will read, not from the shape in memory.
class ModelFeatures {
 public:
  ModelFeatures(const std::filesystem::path& path, std::string name)
      : name_(std::move(name)), features_(cad::classify(cad::read_step_file(path))) {}

  /// The one entity of `kind` whose signature has `type`, `centroid_m` and `direction` (1e-4 m, 1e-3).
  json reference(cad::EntityKind kind, const std::string& type, const Eigen::Vector3d& centroid_m,
                 const Eigen::Vector3d& direction) const {
    std::vector<int> found;
    const auto match = [&](int index, const cad::Signature& s) {
      if (s.type == type && (s.centroid_m - centroid_m).norm() < 1e-4 && (s.direction - direction).norm() < 1e-3)
        found.push_back(index);
    };
    if (kind == cad::EntityKind::kFace) {
      for (const cad::FaceInfo& f : features_.faces) match(f.index, f.signature);
    } else {
      for (const cad::EdgeInfo& e : features_.edges) match(e.index, e.signature);
    }
    if (found.size() != 1)
      throw std::runtime_error("generated cell: " + name_ + " has " + std::to_string(found.size()) + " " +
                               std::string(cad::to_string(kind)) + "s of type " + type + " at " + text(centroid_m) +
                               " along " + text(direction) + ", expected one");
    return to_reference(kind, found.front());
  }

  /// A cylindrical face of the through hole whose entry is at (x, y) in the model frame (1e-4 m).
  json hole(double x, double y) const {
    for (const cad::Hole& h : features_.holes) {
      if ((h.entry_m.head<2>() - Eigen::Vector2d(x, y)).norm() < 1e-4 && !h.faces.empty())
        return to_reference(cad::EntityKind::kFace, h.faces.front());
    }
    throw std::runtime_error("generated cell: " + name_ + " has no hole entering at [" + std::to_string(x) + ", " +
                             std::to_string(y) + "]");
  }

 private:
  json to_reference(cad::EntityKind kind, int index) const {
    // A cell file's reference carries no sha256 (world-model.md: the signature is what is checked).
    json reference = cad::to_json(features_.reference(kind, index));
    reference.erase("model_sha256");
    return reference;
  }

  std::string name_;
  cad::Features features_;
};

// Replaces, in every string value of `node`, a whole value or a "<object>/" prefix by the generated
// cell's name.
void rename(json& node) {
  static const std::vector<std::pair<std::string, std::string>> kNames = {
      {"load/grasp_side", "bracket/grasp_web"},
      {"load/pre_grasp", "bracket/pre_grasp"},
      {"load", "bracket"},
      {"target", "flange"},
      {"hooked(crane,load)", "hooked(crane,bracket)"}};
  if (node.is_object() || node.is_array()) {
    for (json& child : node) rename(child);
    return;
  }
  if (!node.is_string()) return;
  for (const auto& [from, to] : kNames) {
    if (node.get<std::string>() == from) {
      node = to;
      return;
    }
  }
}

}  // namespace

GeneratedCell::GeneratedCell() : GeneratedCell(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json") {}

GeneratedCell::GeneratedCell(const std::filesystem::path& shared_cell_json) : remove_dir_(true) {
  char name[] = "/tmp/rigger_generated_cell_XXXXXX";
  if (::mkdtemp(name) == nullptr) throw std::runtime_error("generated cell: cannot make a folder under /tmp");
  dir_ = name;
  build(shared_cell_json);
}

GeneratedCell::GeneratedCell(std::filesystem::path dir, const std::filesystem::path& shared_cell_json)
    : dir_(std::move(dir)) {
  build(shared_cell_json);
}

GeneratedCell::~GeneratedCell() {
  if (!remove_dir_) return;
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

void GeneratedCell::build(const std::filesystem::path& shipped_cell) {
  const std::filesystem::path models = dir_ / "models";
  std::filesystem::create_directories(models);
  cad::write_step(box({-0.35, -0.5, -kTableTopZ}, {0.35, 0.5, 0.0}), "table", models / "table.step");
  cad::write_step(l_bracket(), "bracket", models / "bracket.step");
  cad::write_step(flange_plate(), "flange", models / "flange.step");
  cad::write_step(box({-0.05, -0.04, -0.03}, {0.05, 0.04, 0.03}), "block", models / "block.step");
  cad::write_step(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -0.05), gp::DZ()), 0.04, 0.10).Shape(), "roller",
                  models / "roller.step");

  std::ifstream shared(shipped_cell);
  if (!shared) throw std::runtime_error("generated cell: cannot read " + shipped_cell.string());
  cell_ = json::parse(shared);
  cell_["description"] = "A generated cell: fixture table, L bracket on the crane, flange plate, three loose parts.";
  json entities = json::array();
  for (const json& entity : cell_["entities"]) {
    if (entity["kind"] != "object") entities.push_back(entity);
  }
  const auto object = [&](const std::string& id, json where, json model) -> json& {
    entities.push_back({{"id", id}, {"kind", "object"}, {"parent", "world"}, {"pose", where}, {"model", model}});
    return entities.back();
  };

  // The table carries the flange where the shipped cell's target stands; the loose parts lie on its far half.
  object("fixture_table", pose(3.60, 2.45, kTableTopZ),
         {{"static", true}, {"step", "models/table.step"}})["localized"] = true;

  // The bracket hangs where the shipped cell's load hangs: the robot grips the web's outer (-x) face, the
  // camera (on +x) sees the markers on the web's inner face.
  const ModelFeatures bracket_model(models / "bracket.step", "models/bracket.step");
  const ModelFeatures flange_model(models / "flange.step", "models/flange.step");
  json& bracket = object("bracket", pose(3.55, 1.75, 1.10), {{"mass_kg", 25.0}, {"step", "models/bracket.step"}});
  bracket["localized"] = false;
  const json web_face = bracket_model.reference(cad::EntityKind::kFace, "plane", {-0.20, 0.0, 0.18}, {-1.0, 0.0, 0.0});
  const json web_edge = bracket_model.reference(cad::EntityKind::kEdge, "line", {-0.20, -0.15, 0.18}, {0.0, 0.0, 1.0});
  const json grasp = {{"rule", "face"}, {"z", "into"}, {"x_reversed", true}, {"face", web_face}, {"x_edge", web_edge}};
  json approach = grasp;
  approach["standoff_m"] = 0.10;
  bracket["features"] = {
      // Above the centre of mass (x = -0.079 m): the bracket hangs level.
      {"rope_attachment", pose(-0.08, 0.0, 0.35)},
      {"grasp_frames", {{{"id", "grasp_web"}, {"cad", grasp}}}},
      {"approach_waypoints", {{{"id", "pre_grasp"}, {"cad", approach}}}},
      {"markers",
       {{"dictionary", "DICT_4X4_50"},
        {"items",
         {{{"id", 1}, {"size_m", 0.08}, {"pose", pose(-0.17, -0.075, 0.18, 90, 0, 90)}},
          {{"id", 2}, {"size_m", 0.08}, {"pose", pose(-0.17, 0.075, 0.18, 90, 0, 90)}}}}}},
      {"insertion",
       {{"target", "flange"},
        {"cad",
         {{"rule", "mate_faces"},
          {"face", bracket_model.reference(cad::EntityKind::kFace, "plane", {0.0, 0.0, 0.0}, {0.0, 0.0, -1.0})},
          {"target_face",
           flange_model.reference(cad::EntityKind::kFace, "plane", {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0})}}}}}};

  // The flange lies on the table, its top face where the shipped cell's target has its top face; its markers
  // are on the lug's outer face, facing the camera as the shipped target's do.
  json& flange =
      object("flange", pose(3.55, 2.25, kTableTopZ + 0.04), {{"static", true}, {"step", "models/flange.step"}});
  flange["localized"] = false;
  json holes = json::array();
  for (int k = 0; k < 6; ++k) {
    const double angle = k * M_PI / 3.0;
    holes.push_back(
        {{"id", "h" + std::to_string(k + 1)},
         {"cad",
          {{"rule", "hole"},
           {"hole", flange_model.hole(kBoltCircleRadius * std::cos(angle), kBoltCircleRadius * std::sin(angle))}}},
         {"screw_type", "M20x60"},
         {"torque_nm", 120}});
  }
  flange["features"] = {
      {"screw_holes", holes},
      {"markers",
       {{"dictionary", "DICT_4X4_50"},
        {"items",
         {{{"id", 10}, {"size_m", 0.08}, {"pose", pose(kLugInnerX + 0.02, -0.06, 0.06, 90, 0, 90)}},
          {{"id", 11}, {"size_m", 0.08}, {"pose", pose(kLugInnerX + 0.02, 0.06, 0.06, 90, 0, 90)}}}}}}};

  // Dropped from 2 mm above the table top, on the half of the table the bracket never passes over.
  object("part_a", pose(3.40, 2.78, kTableTopZ + 0.032), {{"mass_kg", 2.0}, {"step", "models/block.step"}});
  object("part_b", pose(3.60, 2.80, kTableTopZ + 0.052), {{"density_kg_m3", 7850.0}, {"step", "models/roller.step"}});
  object("part_c", pose(3.80, 2.78, kTableTopZ + 0.042),
         {{"shape", "box"}, {"size_m", {0.12, 0.10, 0.08}}, {"mass_kg", 1.5}});
  cell_["entities"] = entities;
}

std::filesystem::path GeneratedCell::write() const {
  const std::filesystem::path path = dir_ / "cell.json";
  std::ofstream out(path);
  out << cell_.dump(2);
  if (!out) throw std::runtime_error("generated cell: cannot write " + path.string());
  return path;
}

NewProductModels write_new_product(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  // The L bracket of the generated cell, two 18 mm through holes in its base plate.
  TopoDS_Compound bracket;
  BRep_Builder builder;
  builder.MakeCompound(bracket);
  builder.Add(bracket, drilled(box({-0.20, -0.15, 0.0}, {0.20, 0.15, 0.03}), {{0.06, -0.09, 0.009}, {0.06, 0.09, 0.009}},
                               -0.01, 0.05));
  builder.Add(bracket, box({-0.20, -0.15, 0.03}, {-0.17, 0.15, 0.33}));
  // The base plate 0.50 x 0.34 x 0.03 m, frame at the centre of its drilled 0.40 m (x from -0.20 to 0.20) on
  // its top face: four 17.5 mm holes on a trapezoid and two 14 mm holes off its axes; at its +x end a marker
  // tab 0.02 x 0.24 x 0.12 m standing on the top face, as a second solid (a camera 23 degrees above the
  // horizon sees markers on the top face at 68 degrees from their normal, too flat for a pose to servo on).
  TopoDS_Compound plate;
  builder.MakeCompound(plate);
  builder.Add(plate, drilled(box({-0.20, -0.17, -0.03}, {0.30, 0.17, 0.0}),
                             {{-0.15, -0.12, 0.00875},
                              {0.15, -0.12, 0.00875},
                              {0.11, 0.12, 0.00875},
                              {-0.11, 0.12, 0.00875},
                              {-0.05, 0.0, 0.007},
                              {0.09, 0.04, 0.007}},
                             -0.04, 0.05));
  builder.Add(plate, box({0.28, -0.12, 0.0}, {0.30, 0.12, 0.12}));
  NewProductModels models{dir / "bracket.step", dir / "base_plate.step"};
  cad::write_step(bracket, "bracket", models.bracket);
  cad::write_step(plate, "base_plate", models.plate);
  return models;
}

CellGeometry GeneratedCell::load() const {
  return load_cell_geometry(write());
}

std::string GeneratedCell::error() const {
  try {
    load();
  } catch (const CellGeometryError& error) {
    return error.what();
  }
  return "";
}

std::size_t GeneratedCell::index_of(const std::string& id) const {
  for (std::size_t i = 0; i < cell_["entities"].size(); ++i) {
    if (cell_["entities"][i]["id"] == id) return i;
  }
  throw std::out_of_range("generated cell: no entity \"" + id + "\"");
}

namespace {
// The skills whose `object` (defaulting to "load") or `target` (defaulting to "target") names a cell object.
const std::set<std::string> kObjectSkills = {"AttachRobotToLoad", "CollaborativeMoveLoad", "InsertVisuallyGuided",
                                             "Release", "Screw"};
const std::set<std::string> kTargetSkills = {"InsertVisuallyGuided", "Screw"};
}  // namespace

nlohmann::json GeneratedCell::recipe(const nlohmann::json& demo_recipe, const std::string& task_id) const {
  json recipe = demo_recipe;
  rename(recipe);
  recipe["task_id"] = task_id;
  // Every hole of the flange, from the cell document: the operator screws all of them.
  json holes = json::array();
  for (const json& hole : cell_["entities"][index_of("flange")]["features"]["screw_holes"])
    holes.push_back("flange/" + hole["id"].get<std::string>());
  std::vector<json*> pending = {&recipe};
  while (!pending.empty()) {
    json& node = *pending.back();
    pending.pop_back();
    if (node.is_object() && node.value("skill", "") == "Screw") node["params"]["holes"] = holes;
    // A skill's object and target default to the shipped cell's names ("load", "target"): a recipe for
    // another cell names its objects in every skill that has them, or the conditions name objects it lacks.
    if (node.is_object() && node.value("type", "") == "Skill") {
      const std::string skill = node.value("skill", "");
      json& params = node["params"];
      if (kObjectSkills.count(skill) != 0 && !params.contains("object")) params["object"] = "bracket";
      if (kTargetSkills.count(skill) != 0 && !params.contains("target")) params["target"] = "flange";
    }
    if (node.is_object() || node.is_array()) {
      for (json& child : node) pending.push_back(&child);
    }
  }
  return recipe;
}

}  // namespace rigger::sim
