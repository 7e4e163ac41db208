// The cell file's CAD rules derived from the real STEP models of the simulated cell
// (deploy/cell/models): the derived frames are the numbers the cell file used to carry by hand, and a
// reference into a changed model, a missing model or a bad reference is refused at the key that says so.

#include <cmath>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "rigger/cad/features.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "rigger/cell_config/cell_cad.hpp"

namespace rigger::cell {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kSource = RIGGER_SOURCE_DIR;
const fs::path kShippedCell = kSource / "deploy/cell/simulated_cell.json";

// The poses the shipped cell file carried as numbers before they were derived from the STEP models
// (the scenario was tuned with them).
struct OldPose {
  const char* entity;
  const char* feature;
  Eigen::Vector3d position_m;
  Eigen::Vector3d rpy_deg;
};
const OldPose kOldPoses[] = {
    {"load", "grasp_side", {-0.20, 0, 0}, {0, 90, 0}},
    {"load", "pre_grasp", {-0.30, 0, 0}, {0, 90, 0}},
    {"target", "h1", {-0.15, -0.10, 0}, {0, 0, 0}},
    {"target", "h2", {0.15, -0.10, 0}, {0, 0, 0}},
    {"target", "h3", {0.15, 0.10, 0}, {0, 0, 0}},
    {"target", "h4", {-0.15, 0.10, 0}, {0, 0, 0}},
};

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

void expect_pose_near(const Eigen::Isometry3d& derived, const Eigen::Isometry3d& expected, const std::string& what) {
  EXPECT_LT((derived.translation() - expected.translation()).norm(), 1e-6)
      << what << ": derived at " << derived.translation().transpose() << ", expected "
      << expected.translation().transpose();
  EXPECT_LT(angle_between(derived.linear(), expected.linear()), 1e-6) << what << ": rotation differs";
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

json& entity_json(json& cell, const std::string& id) {
  for (auto& entity : cell["entities"]) {
    if (entity["id"] == id) return entity;
  }
  throw std::runtime_error("no entity " + id);
}

// A copy of the shipped cell file and its models in a temporary folder, to be edited by a test.
class CellCopy {
 public:
  CellCopy() : dir_(fs::temp_directory_path() / ("rigger_cell_cad_" + std::to_string(::getpid()) + "_" +
                                                 ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "models");
    for (const char* name : {"load.step", "target.step", "part.step", "part_fixture.step"}) {
      fs::copy_file(kSource / "deploy/cell/models" / name, dir_ / "models" / name);
    }
    cell = read_json(kShippedCell);
  }
  ~CellCopy() { fs::remove_all(dir_); }

  const fs::path& dir() const { return dir_; }

  // Writes `cell` and loads it with its CAD features; the error text, or "" when it loads.
  std::string load_error() const {
    const fs::path path = dir_ / "cell.json";
    std::ofstream(path) << cell.dump(2);
    try {
      load_cell_file_with_cad(path);
    } catch (const CellFileError& error) {
      pointer_ = error.pointer();
      return error.what();
    }
    return "";
  }
  const std::string& pointer() const { return pointer_; }

  json cell;

 private:
  fs::path dir_;
  mutable std::string pointer_;
};

TEST(CellCad, DerivedFeaturesOfTheShippedCellAreTheOldHandTypedNumbers) {
  CadDerivation stats;
  const CellFile cell = load_cell_file_with_cad(kShippedCell, &stats);
  EXPECT_EQ(stats.models, 4);    // load, target, part, part_fixture
  EXPECT_EQ(stats.features, 9);  // grasp_side, pre_grasp, h1..h4, insertion, grasp_top, place_top
  EXPECT_NO_THROW(cell.require_cad_derived("this test"));
  for (const OldPose& old : kOldPoses) {
    const auto pose = cell.find(old.entity)->features.find_pose(old.feature);
    ASSERT_TRUE(pose.has_value()) << old.feature;
    expect_pose_near(*pose, pose_from_position_rpy_deg(old.position_m, old.rpy_deg),
                     std::string(old.entity) + "/" + old.feature);
  }
  const auto& insertion = cell.find("load")->features.insertion;
  ASSERT_TRUE(insertion.has_value());
  EXPECT_EQ(insertion->target, "target");
  expect_pose_near(insertion->pose_target_entity, pose_from_position_rpy_deg({0, 0, 0.10}, {0, 0, 0}), "insertion");
  // What is not geometric stays in the cell file.
  for (const auto& hole : cell.find("target")->features.screw_holes) {
    EXPECT_EQ(hole.screw_type, "M12x40");
    EXPECT_EQ(hole.torque_nm, 60.0);
  }
  std::cout << "[ figure ] derived " << stats.features << " features from " << stats.models << " STEP models: read "
            << stats.read_seconds << " s, derive " << stats.derive_seconds << " s\n";
}

TEST(CellCad, TheDerivationNeedsTheStepModels) {
  // Read without deriving: the rules are parsed, their poses not yet there, and a reader that needs them
  // is told so instead of getting identity poses.
  const CellFile cell = load_cell_file(kShippedCell);
  ASSERT_NE(cell.find("load")->features.pending_cad(), nullptr);
  try {
    cell.require_cad_derived("the test");
    FAIL() << "underived rules accepted";
  } catch (const CellFileError& error) {
    EXPECT_NE(std::string(error.what()).find("not derived"), std::string::npos) << error.what();
    EXPECT_NE(error.pointer().find("/features/grasp_frames/0/cad"), std::string::npos) << error.what();
  }
}

TEST(CellCad, AStaleSignatureNamesTheObjectFeatureAndKey) {
  CellCopy copy;
  json& hole = entity_json(copy.cell, "target")["features"]["screw_holes"][0];
  ASSERT_EQ(hole["id"], "h1");
  hole["cad"]["hole"]["signature"]["centroid_m"][0] = -0.151;  // 1 mm off what the model says
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_STALE_REFERENCE"), std::string::npos) << error;
  EXPECT_NE(error.find("feature \"h1\" of \"target\""), std::string::npos) << error;
  EXPECT_NE(error.find("models/target.step"), std::string::npos) << error;
  EXPECT_TRUE(copy.pointer().find("/features/screw_holes/0/cad/hole") != std::string::npos) << copy.pointer();
}

TEST(CellCad, AChangedModelIsDetected) {
  // The target's STEP file is edited: hole h1 drilled 5 mm further out. The references into it no
  // longer match (h1's hole, and the top face, whose centroid moved with the hole): the first one met
  // (the load's insertion onto the top face) is reported.
  CellCopy copy;
  const auto size_values = entity_json(copy.cell, "target")["model"]["size_m"].get<std::vector<double>>();
  const Eigen::Vector3d size(size_values.at(0), size_values.at(1), size_values.at(2));
  auto holes = cad::parts::cell_target_holes();
  holes[0].entry_m.x() -= 0.005;
  const Eigen::Vector3d half(size.x() / 2, size.y() / 2, 0.0);
  cad::write_step(cad::parts::drilled_box(-half - Eigen::Vector3d(0, 0, size.z()), half, holes), "target",
                  copy.dir() / "models/target.step");
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_STALE_REFERENCE"), std::string::npos) << error;
  EXPECT_NE(error.find("of models/target.step"), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/cad/"), std::string::npos) << copy.pointer();
}

std::string file_sha256(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return cad::sha256_hex(std::string(std::istreambuf_iterator<char>(in), {}));
}

TEST(CellCad, APinnedModelIsReadWithExactlyItsBytes) {
  CellCopy copy;
  const std::string load_sha = file_sha256(copy.dir() / "models/load.step");
  entity_json(copy.cell, "load")["model"]["sha256"] = load_sha;
  EXPECT_EQ(copy.load_error(), "");
  // Other bytes under the same name (another host's file, an edit): refused at the pin, naming both digests.
  fs::copy_file(copy.dir() / "models/part.step", copy.dir() / "models/load.step", fs::copy_options::overwrite_existing);
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_STALE_MODEL"), std::string::npos) << error;
  EXPECT_NE(error.find(load_sha), std::string::npos) << error;
  EXPECT_NE(error.find(file_sha256(copy.dir() / "models/part.step")), std::string::npos) << error;
  EXPECT_EQ(copy.pointer(), "/entities/5/model/sha256") << error;
}

TEST(CellCad, AMissingStepFileIsNamed) {
  CellCopy copy;
  fs::remove(copy.dir() / "models/load.step");
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_FILE_NOT_FOUND"), std::string::npos) << error;
  EXPECT_NE(error.find("\"load\""), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/model/step"), std::string::npos) << copy.pointer();
}

TEST(CellCad, AnUnreadableStepFileIsNamed) {
  CellCopy copy;
  std::ofstream(copy.dir() / "models/target.step") << "ISO-10303-21;\nHEADER;\nthis is not STEP\n";
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_NOT_STEP"), std::string::npos) << error;
  EXPECT_NE(error.find("\"target\""), std::string::npos) << error;
}

TEST(CellCad, AStepFileWithoutALengthUnitIsRefusedNotGuessed) {
  CellCopy copy;
  const fs::path target = copy.dir() / "models/target.step";
  std::ifstream in(target, std::ios::binary);
  const std::string step((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string unitless = std::regex_replace(step, std::regex(R"(GLOBAL_UNIT_ASSIGNED_CONTEXT\s*\(\([^)]*\)\))"), "");
  ASSERT_NE(unitless, step);
  std::ofstream(target, std::ios::binary | std::ios::trunc) << unitless;
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("CAD_NO_UNITS"), std::string::npos) << error;
  EXPECT_NE(error.find("\"target\""), std::string::npos) << error;
  EXPECT_NE(error.find("length unit"), std::string::npos) << error;
}

TEST(CellCad, StaticObjectsGivenByTheirStepModelsMayTouchButNotOverlap) {
  // The target given by its STEP model alone, static beside the static part fixture (a box): apart.
  CellCopy copy;
  json& target = entity_json(copy.cell, "target")["model"];
  target.erase("shape");
  target.erase("size_m");
  target.erase("frame");
  EXPECT_EQ(copy.load_error(), "");
  // The fixture moved onto the target: refused at the fixture's pose, naming the target.
  entity_json(copy.cell, "part_fixture")["pose"]["position_m"] = {3.55, 2.25, 0.95};
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("static objects apart"), std::string::npos) << error;
  EXPECT_NE(error.find("cm³ with static object \"target\""), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/pose"), std::string::npos) << copy.pointer();
}

TEST(CellCad, AMovedIndexWithAUniqueSignatureIsFollowed) {
  // The reference's index is wrong but its signature names exactly one edge of the model: that edge.
  CellCopy copy;
  entity_json(copy.cell, "load")["features"]["grasp_frames"][0]["cad"]["x_edge"]["index"] = 999;
  EXPECT_EQ(copy.load_error(), "");
}

TEST(CellCad, AnIndexOutsideTheModelIsRefused) {
  CellCopy copy;
  json& edge = entity_json(copy.cell, "load")["features"]["grasp_frames"][0]["cad"]["x_edge"];
  edge["index"] = 999;
  edge["signature"]["centroid_m"][2] = 0.05;  // and no edge has this signature
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("feature \"grasp_side\" of \"load\""), std::string::npos) << error;
  EXPECT_NE(error.find("no longer exists"), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/features/grasp_frames/0/cad/x_edge"), std::string::npos) << copy.pointer();
}

TEST(CellCad, AHoleRuleOnAFaceThatIsNoHoleIsRefused) {
  CellCopy copy;
  json& hole = entity_json(copy.cell, "target")["features"]["screw_holes"][1];
  hole["cad"]["hole"] = entity_json(copy.cell, "load")["features"]["insertion"]["cad"]["target_face"];
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("not part of a hole"), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/features/screw_holes/1/cad/hole"), std::string::npos) << copy.pointer();
}

// The cell file's reference to one cylindrical face of hole `hole` of the shipped model `step`.
json hole_reference(const std::string& step, int hole) {
  const cad::Model model = cad::read_step_file(kSource / "deploy/cell/models" / step);
  const cad::Features features = cad::classify(model);
  const int face = features.holes.at(static_cast<std::size_t>(hole)).faces.at(0);
  const cad::Signature& sig = features.faces.at(static_cast<std::size_t>(face)).signature;
  const auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  return {{"kind", "face"},
          {"index", face},
          {"signature",
           {{"type", sig.type}, {"centroid_m", vec(sig.centroid_m)}, {"direction", vec(sig.direction)},
            {"radius_m", sig.radius_m}}}};
}

// The shipped load's insertion, pinned: its hole `own` on the target's hole `target` (and a second pair).
json pins(std::initializer_list<std::pair<int, int>> pairs) {
  json out = json::array();
  for (const auto& [own, target] : pairs)
    out.push_back({{"hole", hole_reference("load.step", own)}, {"target_hole", hole_reference("target.step", target)}});
  return out;
}

TEST(CellCad, OnePinMovesTheMatedPartAlongTheFaceUntilTheHolesShareTheirAxis) {
  // The load's hole 0 (at -0.15, -0.1 on its bottom) on the target's hole 3 (at 0.15, 0.1): the faces
  // stay mated and turned as without the pin, the load slides 0.3 m along x and 0.2 m along y.
  CellCopy copy;
  entity_json(copy.cell, "load")["features"]["insertion"]["cad"]["pins"] = pins({{0, 3}});
  ASSERT_EQ(copy.load_error(), "");
  const CellFile cell = load_cell_file_with_cad(copy.dir() / "cell.json");
  expect_pose_near(cell.find("load")->features.insertion->pose_target_entity,
                   pose_from_position_rpy_deg({0.3, 0.2, 0.10}, {0, 0, 0}), "insertion with one pin");
}

TEST(CellCad, TwoPinsAlsoTurnThePartAboutTheFacesNormal) {
  // Hole 0 on hole 3 and hole 3 on hole 0: the load turned half a turn about z, in place.
  CellCopy copy;
  entity_json(copy.cell, "load")["features"]["insertion"]["cad"]["pins"] = pins({{0, 3}, {3, 0}});
  ASSERT_EQ(copy.load_error(), "");
  const CellFile cell = load_cell_file_with_cad(copy.dir() / "cell.json");
  expect_pose_near(cell.find("load")->features.insertion->pose_target_entity,
                   pose_from_position_rpy_deg({0, 0, 0.10}, {0, 0, 180}), "insertion with two pins");
}

TEST(CellCad, PinsThatCannotBothFitAreRefusedWithTheirSpans) {
  // The load's holes 0 and 1 are 300 mm apart; the target's 0 and 2 are 200 mm apart.
  CellCopy copy;
  entity_json(copy.cell, "load")["features"]["insertion"]["cad"]["pins"] = pins({{0, 0}, {1, 2}});
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("300 mm apart on \"load\", 200 mm on \"target\""), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/features/insertion/cad/pins/1"), std::string::npos) << copy.pointer();
}

TEST(CellCad, APinOnAFaceThatIsNoHoleIsRefused) {
  CellCopy copy;
  json& insertion = entity_json(copy.cell, "load")["features"]["insertion"]["cad"];
  insertion["pins"] = pins({{0, 0}});
  insertion["pins"][0]["target_hole"] = insertion["target_face"];
  const std::string error = copy.load_error();
  EXPECT_NE(error.find("not part of a hole"), std::string::npos) << error;
  EXPECT_NE(copy.pointer().find("/features/insertion/cad/pins/0/target_hole"), std::string::npos) << copy.pointer();
}

TEST(CellCadSchema, RulesAreCheckedWhenTheFileIsRead) {
  const json shipped = read_json(kShippedCell);
  const auto expect_error = [](const json& cell, const std::string& pointer, const std::string& text) {
    try {
      cell_file_from_json(cell, "cell.json");
      ADD_FAILURE() << "accepted; expected an error at " << pointer;
    } catch (const CellFileError& error) {
      EXPECT_EQ(error.pointer(), pointer) << error.what();
      EXPECT_NE(std::string(error.what()).find(text), std::string::npos) << error.what();
    }
  };
  {  // both numbers and a rule
    json cell = shipped;
    json& grasp = entity_json(cell, "load")["features"]["grasp_frames"][0];
    grasp["pose"] = {{"position_m", {0, 0, 0}}, {"rpy_deg", {0, 0, 0}}};
    expect_error(cell, "/entities/5/features/grasp_frames/0/cad", "either \"pose\" (numbers) or \"cad\"");
  }
  {  // neither
    json cell = shipped;
    entity_json(cell, "target")["features"]["screw_holes"][2].erase("cad");
    expect_error(cell, "/entities/6/features/screw_holes/2/pose", "neither");
  }
  {  // a rule on an object without a STEP model
    json cell = shipped;
    entity_json(cell, "load")["model"].erase("step");
    expect_error(cell, "/entities/5/features/grasp_frames/0/cad", "only on an object whose model names a STEP file");
  }
  {  // a rule that does not fit the feature
    json cell = shipped;
    entity_json(cell, "target")["features"]["screw_holes"][0]["cad"]["rule"] = "face";
    expect_error(cell, "/entities/6/features/screw_holes/0/cad/rule", "\"hole\" here");
  }
  {  // a key of another rule
    json cell = shipped;
    entity_json(cell, "target")["features"]["screw_holes"][0]["cad"]["standoff_m"] = 0.1;
    expect_error(cell, "/entities/6/features/screw_holes/0/cad/standoff_m", "only in a \"face\" rule");
  }
  {  // an unknown key in a signature
    json cell = shipped;
    entity_json(cell, "load")["features"]["grasp_frames"][0]["cad"]["face"]["signature"]["normal"] = {1, 0, 0};
    expect_error(cell, "/entities/5/features/grasp_frames/0/cad/face/signature/normal", "unknown key");
  }
  {  // an edge where a face is needed
    json cell = shipped;
    entity_json(cell, "load")["features"]["grasp_frames"][0]["cad"]["face"]["kind"] = "edge";
    expect_error(cell, "/entities/5/features/grasp_frames/0/cad/face/kind", "\"face\"");
  }
  {  // a pin that is no sha256
    json cell = shipped;
    entity_json(cell, "load")["model"]["sha256"] = "abc";
    expect_error(cell, "/entities/5/model/sha256", "64 hex digits");
  }
  {  // a pin without a STEP model
    json cell = shipped;
    entity_json(cell, "load")["model"] = {
        {"shape", "box"}, {"size_m", {0.1, 0.1, 0.1}}, {"sha256", std::string(64, 'a')}};
    expect_error(cell, "/entities/5/model/sha256", "a STEP model");
  }
  {  // pins in a rule that is not mate_faces, and three pins
    json cell = shipped;
    entity_json(cell, "target")["features"]["screw_holes"][0]["cad"]["pins"] = json::array();
    expect_error(cell, "/entities/6/features/screw_holes/0/cad/pins", "only in a \"mate_faces\" rule");
    json three = shipped;
    json& rule = entity_json(three, "load")["features"]["insertion"]["cad"];
    const json pin = {{"hole", rule["face"]}, {"target_hole", rule["target_face"]}};
    rule["pins"] = json::array({pin, pin, pin});
    expect_error(three, "/entities/5/features/insertion/cad/pins", "one or two pins");
  }
  {  // an insertion target without a STEP model
    json cell = shipped;
    entity_json(cell, "target")["model"].erase("step");
    entity_json(cell, "target")["features"].erase("screw_holes");
    expect_error(cell, "/entities/5/features/insertion/cad/target_face", "whose model names a STEP file");
  }
}

}  // namespace
}  // namespace rigger::cell
