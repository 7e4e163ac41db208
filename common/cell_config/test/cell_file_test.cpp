#include <cmath>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell {
namespace {

using nlohmann::json;

// A frozen copy of the simulated cell: hand-computed expectations rely on its numbers.
const std::string kCellFile = std::string(RIGGER_SOURCE_DIR) + "/common/cell_config/test/data/cell_fixture.json";
// The deployed cell file (the contract, which may change).
const std::string kShippedCell = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";

json shipped_cell() {
  std::ifstream file(kCellFile);
  return json::parse(file);
}

// Index of an entity in the shipped file, so the tests read like the file.
std::size_t index_of(const json& cell, const std::string& id) {
  for (std::size_t i = 0; i < cell["entities"].size(); ++i) {
    if (cell["entities"][i]["id"] == id) return i;
  }
  ADD_FAILURE() << "no entity " << id << " in the shipped cell";
  return 0;
}

// Asserts that parsing `document` fails at `pointer` with a message containing `expected`.
void expect_error(const json& document, const std::string& pointer, const std::string& expected) {
  try {
    cell_file_from_json(document, "cell.json");
    ADD_FAILURE() << "expected an error at " << pointer;
  } catch (const CellFileError& error) {
    EXPECT_EQ(error.file(), "cell.json");
    EXPECT_EQ(error.pointer(), pointer) << error.what();
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
    EXPECT_EQ(
        std::string(error.what()).rfind("cell.json: " + (pointer.empty() ? std::string("(document)") : pointer), 0), 0u)
        << error.what();
  }
}

void expect_text_error(const std::string& text, const std::string& pointer, const std::string& expected) {
  try {
    parse_cell_file(std::string_view(text), "cell.json");
    ADD_FAILURE() << "expected an error at " << pointer;
  } catch (const CellFileError& error) {
    EXPECT_EQ(error.pointer(), pointer) << error.what();
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
  }
}

TEST(CellFile, LoadsTheCellFixture) {
  const CellFile config = load_cell_file(kCellFile);
  EXPECT_EQ(config.cell_version, 1);
  EXPECT_EQ(config.source, kCellFile);
  ASSERT_EQ(config.entities.size(), 7u);
  const auto find = [&](const std::string& id) -> const CellEntity& {
    for (const auto& entity : config.entities) {
      if (entity.id == id) return entity;
    }
    throw std::runtime_error("missing " + id);
  };
  const CellEntity& world = find("world");
  EXPECT_EQ(world.kind, EntityKind::kFrame);
  EXPECT_TRUE(world.parent.empty());
  EXPECT_FALSE(world.pose_parent_entity.has_value());

  const CellEntity& robot = find("robot");
  EXPECT_EQ(robot.kind, EntityKind::kDevice);
  EXPECT_EQ(robot.parent, "world");
  ASSERT_TRUE(robot.pose_parent_entity.has_value());
  EXPECT_TRUE(robot.pose_parent_entity->translation().isApprox(Eigen::Vector3d(2.55, 2.0, 0.9)));
  EXPECT_TRUE(robot.localized) << "calibrated devices are localized by the configuration";
  EXPECT_EQ(robot.attributes["model"], "kuka_lbr_iiwa_14_r820");

  const CellEntity& gripper = find("gripper");
  EXPECT_FALSE(gripper.pose_parent_entity.has_value());
  EXPECT_FALSE(gripper.localized);

  const CellEntity& camera = find("camera");
  ASSERT_TRUE(camera.camera.has_value());
  EXPECT_EQ(camera.camera->width_px, 1280);
  EXPECT_EQ(camera.camera->height_px, 720);
  EXPECT_DOUBLE_EQ(camera.camera->fx_px, 1000.0);
  EXPECT_DOUBLE_EQ(camera.camera->cy_px, 360.0);
  EXPECT_EQ(camera.camera->distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(camera.camera->rate_hz, 30.0);
  EXPECT_DOUBLE_EQ(camera.camera->noise_stddev, 2.0);
  EXPECT_DOUBLE_EQ(camera.camera->camera_matrix()(0, 2), 640.0);
  // Camera rotated by roll -130 deg: R = Rx(-130 deg), written out by hand.
  const double c = std::cos(-130.0 * M_PI / 180.0);
  const double s = std::sin(-130.0 * M_PI / 180.0);
  Eigen::Matrix3d rx;
  rx << 1, 0, 0, 0, c, -s, 0, s, c;
  EXPECT_TRUE(camera.pose_parent_entity->linear().isApprox(rx, 1e-12));

  const CellEntity& load = find("load");
  EXPECT_EQ(load.kind, EntityKind::kObject);
  EXPECT_FALSE(load.localized);
  ASSERT_TRUE(load.model.has_value());
  EXPECT_EQ(load.model->shape, "box");
  EXPECT_TRUE(load.model->size_m.isApprox(Eigen::Vector3d(0.40, 0.30, 0.20)));
  ASSERT_TRUE(load.model->mass_kg.has_value());
  EXPECT_DOUBLE_EQ(*load.model->mass_kg, 40.0);
  ASSERT_EQ(load.features.grasp_frames.size(), 1u);
  EXPECT_EQ(load.features.grasp_frames[0].id, "grasp_side");
  // rpy (0, 90, 0): R = Ry(90 deg) = [[0,0,1],[0,1,0],[-1,0,0]]; tool z into the -x face, tool x down.
  Eigen::Matrix3d ry90;
  ry90 << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  EXPECT_TRUE(load.features.grasp_frames[0].pose_entity_feature.linear().isApprox(ry90, 1e-12));
  EXPECT_TRUE(load.features.grasp_frames[0].pose_entity_feature.translation().isApprox(Eigen::Vector3d(-0.20, 0, 0)));
  ASSERT_TRUE(load.features.rope_attachment.has_value());
  ASSERT_EQ(load.features.approach_waypoints.size(), 1u);
  ASSERT_TRUE(load.features.markers.has_value());
  EXPECT_EQ(load.features.markers->dictionary, "DICT_4X4_50");
  ASSERT_EQ(load.features.markers->items.size(), 2u);
  EXPECT_EQ(load.features.markers->items[1].id, 2);
  EXPECT_DOUBLE_EQ(load.features.markers->items[1].size_m, 0.08);
  ASSERT_TRUE(load.features.insertion.has_value());
  EXPECT_EQ(load.features.insertion->target, "target");
  EXPECT_TRUE(load.features.insertion->pose_target_entity.translation().isApprox(Eigen::Vector3d(0, 0, 0.10)));

  const CellEntity& target = find("target");
  ASSERT_EQ(target.features.screw_holes.size(), 4u);
  EXPECT_EQ(target.features.screw_holes[2].id, "h3");
  EXPECT_EQ(target.features.screw_holes[2].screw_type, "M12x40");
  EXPECT_DOUBLE_EQ(target.features.screw_holes[2].torque_nm, 60.0);
  EXPECT_TRUE(target.model->is_static);
}

TEST(CellFile, LoadsTheDeployedCell) {
  // The contract file may change; it must load, and every entity must keep the position it states.
  const CellFile config = load_cell_file(kShippedCell);
  std::ifstream file(kShippedCell);
  const json raw = json::parse(file);
  ASSERT_EQ(config.entities.size(), raw["entities"].size());
  for (std::size_t i = 0; i < config.entities.size(); ++i) {
    const json& entity = raw["entities"][i];
    EXPECT_EQ(config.entities[i].id, entity["id"]);
    EXPECT_EQ(config.entities[i].pose_parent_entity.has_value(), entity.contains("pose")) << entity["id"];
    if (entity.contains("pose")) {
      const auto& p = entity["pose"]["position_m"];
      EXPECT_TRUE(config.entities[i].pose_parent_entity->translation().isApprox(
          Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>())))
          << entity["id"];
    }
  }
}

TEST(CellFile, RpyConventionIsZYX) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): roll 90 then yaw 90 maps x -> y, y -> z, z -> x.
  const Eigen::Matrix3d r = rotation_from_rpy_deg(Eigen::Vector3d(90, 0, 90));
  EXPECT_TRUE((r * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((r * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_TRUE((r * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
}

TEST(CellFile, EntitiesMayBeListedBeforeTheirParent) {
  json cell = shipped_cell();
  std::swap(cell["entities"][0], cell["entities"][2]);  // robot's child gripper before world and robot
  EXPECT_EQ(cell_file_from_json(cell, "cell.json").entities.size(), 7u);
}

TEST(CellFile, CommentsAreAllowedEverywhere) {
  json cell = shipped_cell();
  cell["comment"] = "top";
  cell["entities"][1]["comment"] = "entity";
  cell["entities"][1]["pose"]["comment"] = "pose";
  EXPECT_NO_THROW(cell_file_from_json(cell, "cell.json"));
  cell["entities"][1]["comment"] = 3;
  expect_error(cell, "/entities/1/comment", "a string");
}

// Sets `value` at `path` inside entity `id` of the shipped cell (or removes the key when `value` is
// discarded) and expects the error at that place, containing `expected`.
void expect_entity_error(const std::string& id, const std::string& path, const json& value,
                         const std::string& expected) {
  json cell = shipped_cell();
  const std::string pointer = "/entities/" + std::to_string(index_of(cell, id)) + path;
  const json::json_pointer where(pointer);
  if (value.is_discarded()) {
    cell[where.parent_pointer()].erase(where.back());
  } else {
    cell[where] = value;
  }
  expect_error(cell, pointer, expected);
}

const json kRemove = json(json::value_t::discarded);

TEST(CellFile, RejectsAMissingParent) {
  expect_entity_error("gripper", "/parent", "nowhere", "unknown entity \"nowhere\"");
}

TEST(CellFile, RejectsANonFrameWithoutParent) {
  expect_entity_error("crane", "/parent", kRemove, "only frames may be roots");
}

TEST(CellFile, RejectsAPoseOnARootFrame) {
  expect_entity_error("world", "/pose", {{"position_m", {0, 0, 0}}, {"rpy_deg", {0, 0, 0}}}, "no pose on a root frame");
}

TEST(CellFile, RejectsAnUnknownKind) {
  expect_entity_error("crane", "/kind", "robot", "\"object\", \"device\" or \"frame\"");
}

TEST(CellFile, RejectsABadRpyLength) {
  expect_entity_error("crane", "/pose/rpy_deg", {0, 0}, "an array of 3 numbers");
}

TEST(CellFile, RejectsNaN) {
  expect_entity_error("crane", "/pose/position_m/0", std::numeric_limits<double>::quiet_NaN(), "a finite number");
  expect_entity_error("crane", "/attributes/rated_load_kg", std::numeric_limits<double>::infinity(), "a finite number");
}

TEST(CellFile, RejectsNumberOverflowInText) {
  // JSON has no infinity literal; 1e999 overflows a double and is refused by the parser.
  json cell = shipped_cell();
  cell["entities"][1]["pose"]["rpy_deg"] = {0, 0, 0};
  std::string text = cell.dump();
  const std::string rpy = "\"rpy_deg\":[0,0,0]";
  ASSERT_NE(text.find(rpy), std::string::npos);
  text.replace(text.find(rpy), rpy.size(), "\"rpy_deg\":[0,0,1e999]");
  expect_text_error(text, "", "number overflow parsing '1e999'");
}

TEST(CellFile, RejectsADuplicateId) {
  json cell = shipped_cell();
  cell["entities"][2]["id"] = cell["entities"][1]["id"];
  expect_error(cell, "/entities/2/id", "already used at /entities/1");
}

TEST(CellFile, RejectsACycleInTheFrameTree) {
  expect_entity_error("robot", "/parent", "gripper", "the cycle robot -> gripper -> robot");  // gripper hangs on robot
  expect_entity_error("robot", "/parent", "robot", "the entity itself");
}

TEST(CellFile, StaticBoxesMayTouchButNotOverlap) {
  json cell = shipped_cell();
  const std::size_t target = index_of(cell, "target");
  // A second static box like the target (0.95 m high, its frame at the centre of its top face) on top of it.
  json stand = cell["entities"][target];
  stand["id"] = "stand";
  stand.erase("features");
  stand["pose"]["position_m"][2] = stand["pose"]["position_m"][2].get<double>() + 0.95;
  cell["entities"].push_back(stand);
  EXPECT_NO_THROW(cell_file_from_json(cell, "cell.json")) << "the stand touches the target";
  json& pose = cell["entities"].back()["pose"];
  pose["position_m"][2] = pose["position_m"][2].get<double>() - 0.1;
  expect_error(cell, "/entities/" + std::to_string(cell["entities"].size() - 1) + "/pose",
               "overlaps static object \"target\" (/entities/" + std::to_string(target) + ") by 100 mm");
}

TEST(CellFile, RejectsUnknownKeysEverywhere) {
  json cell = shipped_cell();
  cell["entitys"] = json::array();
  expect_error(cell, "/entitys", "unknown key \"entitys\"");
  expect_entity_error("crane", "/posture", 1, "unknown key");
  expect_entity_error("crane", "/pose/position", {0, 0, 0}, "one of the keys {position_m, rpy_deg, comment}");
  expect_entity_error("crane", "/pose/a~1b~0c", 1, "unknown key \"a/b~c\"");
  expect_entity_error("camera", "/camera/k1", 0.1, "unknown key");
  expect_entity_error("load", "/features/grasps", json::array(), "unknown key");
  expect_entity_error("load", "/model/colour", "red", "unknown key");
  expect_entity_error("load", "/features/markers/items/0/side", 0.08, "unknown key");
  expect_entity_error("target", "/features/screw_holes/0/torque", 60, "unknown key");
}

TEST(CellFile, RejectsMissingRequiredKeys) {
  json cell = shipped_cell();
  cell.erase("cell_version");
  expect_error(cell, "/cell_version", "format version 1");
  expect_entity_error("crane", "/id", kRemove, "missing key");
  expect_entity_error("crane", "/kind", kRemove, "missing key");
  expect_entity_error("crane", "/pose/position_m", kRemove, "[x, y, z] in metres");
  expect_entity_error("camera", "/camera/fx", kRemove, "focal length");
  expect_entity_error("target", "/features/screw_holes/2/screw_type", kRemove, "screw type");
}

TEST(CellFile, RejectsWrongTypesAndRanges) {
  json cell = shipped_cell();
  cell["cell_version"] = 2;
  expect_error(cell, "/cell_version", "an integer in [1, 1]");
  cell = shipped_cell();
  cell["entities"] = json::array();
  expect_error(cell, "/entities", "a non-empty array");
  expect_entity_error("crane", "/id", "has space", "an identifier");
  expect_entity_error("crane", "/localized", "yes", "true or false");
  expect_entity_error("gripper", "/localized", true, "false for an entity without a pose");
  expect_entity_error("crane", "/attributes", json::array(), "an object");
  expect_entity_error("camera", "/camera/width", 1280.5, "an integer");
  expect_entity_error("camera", "/camera/fx", -1, "a number > 0");
  expect_entity_error("camera", "/camera/cx", 2000, "inside the image");
  expect_entity_error("camera", "/camera/distortion", {0, 0, 0}, "4, 5, 8, 12 or 14 numbers");
  expect_entity_error("load", "/model/size_m", {0.4, 0, 0.2}, "three extents > 0 m");
  expect_entity_error("load", "/model/shape", "mesh", "\"box\"");
  // A geometry is the box shorthand or the STEP model alone; a mass or a density, not both.
  expect_entity_error("load", "/model", json{{"mass_kg", 40.0}},
                      "a geometry: \"shape\": \"box\" with \"size_m\", or a STEP model");
  expect_entity_error("load", "/model/density_kg_m3", 7850.0, "either mass_kg or density_kg_m3, not both");
  expect_entity_error("target", "/features/screw_holes/1/torque_nm", 0, "a number > 0");
  expect_entity_error("target", "/features/screw_holes/0/screw_type", "", "non-empty screw type");
}

TEST(CellFile, RejectsMisplacedSections) {
  const json cell = shipped_cell();
  expect_entity_error("load", "/camera", cell["entities"][index_of(cell, "camera")]["camera"],
                      "camera intrinsics only on a device");
  expect_entity_error("robot", "/model", cell["entities"][index_of(cell, "load")]["model"],
                      "an object model only on an object");
  expect_entity_error("world", "/features", json::object(), "no features on a frame");
}

TEST(CellFile, RejectsFeatureErrors) {
  const json cell = shipped_cell();
  const std::string load_features = "/entities/" + std::to_string(index_of(cell, "load")) + "/features";
  expect_entity_error("load", "/features/approach_waypoints/0/id", "grasp_side",
                      "already used at " + load_features + "/grasp_frames/0/id");
  expect_entity_error("target", "/features/markers/items/0/id", 2,  // the load's marker 2, same dictionary
                      "unique in the cell for dictionary DICT_4X4_50, got 2, already used at " + load_features);
  expect_entity_error("load", "/features/markers/items/1/id", 1, "unique within the layout");
  expect_entity_error("load", "/features/markers/items/0/id", 50, "an integer in [0, 49]");  // DICT_4X4_50
  expect_entity_error("load", "/features/markers/dictionary", "DICT_9X9_50", "OpenCV predefined dictionary");
  expect_entity_error("load", "/features/insertion/target", "fixture", "another entity of this cell");
  expect_entity_error("load", "/features/insertion/target", "load", "another entity of this cell");
  // The crane carries one load: a second object with a rope attachment is refused where it is declared.
  expect_entity_error("target", "/features/rope_attachment", cell["entities"][index_of(cell, "load")]["features"]["rope_attachment"],
                      "one object with a rope attachment (the crane carries one load), got a second one: \"load\" has one");
}

TEST(CellFile, RejectsMalformedJsonText) {
  expect_text_error("{ \"cell_version\": 1, ", "", "valid JSON");
  expect_text_error("", "", "valid JSON");
}

TEST(CellFile, RejectsDuplicateKeysWhileParsing) {
  expect_text_error(R"({"cell_version": 1, "entities": [{"id": "world", "kind": "frame", "id": "w2"}]})",
                    "/entities/0/id", "duplicate key \"id\"");
}

TEST(CellFile, BoundsNestingWhileParsing) {
  const std::string deep = std::string(1000, '[') + std::string(1000, ']');
  try {
    parse_cell_file(std::string_view(deep), "deep.json");
    ADD_FAILURE() << "expected a nesting error";
  } catch (const CellFileError& error) {
    EXPECT_NE(std::string(error.what()).find("nesting deeper than 32"), std::string::npos) << error.what();
  }
}

TEST(CellFile, BoundsInputSize) {
  const std::string huge(kMaxCellFileBytes + 1, ' ');
  EXPECT_THROW(parse_cell_file(std::string_view(huge), "huge.json"), CellFileError);
}

TEST(CellFile, NamesAnUnreadableFile) {
  try {
    load_cell_file("/nonexistent/cell.json");
    ADD_FAILURE() << "expected an error";
  } catch (const CellFileError& error) {
    EXPECT_EQ(error.file(), "/nonexistent/cell.json");
    EXPECT_NE(std::string(error.what()).find("a readable file"), std::string::npos);
  }
}

TEST(CellFile, ComposesPosesThroughParents) {
  json cell = shipped_cell();
  cell["entities"].push_back({{"id", "bench"},
                              {"kind", "frame"},
                              {"parent", "world"},
                              {"pose", {{"position_m", {1, 0, 0}}, {"rpy_deg", {0, 0, 90}}}}});
  cell["entities"][index_of(cell, "target")]["parent"] = "bench";
  const CellFile file = cell_file_from_json(cell, "cell.json");
  // The target at (3.55, 2.25, 0.95) in a frame yawed 90 deg and shifted 1 m in x.
  EXPECT_TRUE(file.pose_root_entity("target").translation().isApprox(Eigen::Vector3d(1 - 2.25, 3.55, 0.95), 1e-12));
  // An entity without a pose sits at its parent's origin.
  EXPECT_TRUE(file.pose_root_entity("gripper").isApprox(file.pose_root_entity("robot")));
  EXPECT_TRUE(file.pose_root_entity("world").isApprox(Eigen::Isometry3d::Identity()));
}

TEST(CellFile, RequireNamesTheMissingEntity) {
  const CellFile file = load_cell_file(kCellFile);
  EXPECT_EQ(&file.require("load", "the load"), file.find("load"));
  EXPECT_EQ(file.find("magnet"), nullptr);
  try {
    file.require("magnet", "the gripper of the physics");
    ADD_FAILURE() << "expected an error";
  } catch (const CellFileError& error) {
    EXPECT_EQ(error.pointer(), "/entities");
    EXPECT_NE(std::string(error.what()).find("an entity with id \"magnet\" (the gripper of the physics)"),
              std::string::npos)
        << error.what();
  }
}

// The error of reading attribute `key` of entity `id` with `read`, or "" when it reads.
template <typename Read>
std::string attribute_error(const json& cell, const std::string& id, Read read) {
  const CellFile file = cell_file_from_json(cell, "cell.json");
  try {
    read(AttributeReader(file, file.require(id, "test")));
  } catch (const CellFileError& error) {
    return error.what();
  }
  return "";
}

TEST(AttributeReader, ReadsCheckedAttributes) {
  const CellFile file = load_cell_file(kCellFile);
  const AttributeReader crane(file, file.require("crane", "test"));
  EXPECT_DOUBLE_EQ(crane.positive("rail_height_m"), 4.5);
  EXPECT_TRUE(crane.range("bridge_range_m").isApprox(Eigen::Vector2d(0.0, 8.0)));
  EXPECT_TRUE(crane.positive3("max_speed_mps").isApprox(Eigen::Vector3d(0.5, 0.5, 0.2)));
  EXPECT_EQ(AttributeReader(file, file.require("robot", "test")).text("model"), "kuka_lbr_iiwa_14_r820");
  EXPECT_EQ(crane.pointer("rated_load_kg"), "/entities/1/attributes/rated_load_kg");
}

TEST(AttributeReader, ErrorsNameFilePointerAndExpectation) {
  json cell = shipped_cell();
  const std::string crane = "cell.json: /entities/" + std::to_string(index_of(cell, "crane")) + "/attributes/";
  auto& attributes = cell["entities"][index_of(cell, "crane")]["attributes"];
  attributes.erase("rail_height_m");
  attributes["bridge_range_m"] = {8.0, 0.0};
  attributes["max_speed_mps"] = {0.5, 0.0, 0.2};
  attributes["rated_load_kg"] = "heavy";
  EXPECT_EQ(attribute_error(cell, "crane", [](const AttributeReader& r) { r.positive("rail_height_m"); }),
            crane + "rail_height_m: expected a number > 0, got nothing (missing key)");
  EXPECT_EQ(attribute_error(cell, "crane", [](const AttributeReader& r) { r.range("bridge_range_m"); }),
            crane + "bridge_range_m: expected [min, max], two numbers with min < max, got array [8.0,0.0]");
  EXPECT_EQ(attribute_error(cell, "crane", [](const AttributeReader& r) { r.positive3("max_speed_mps"); }),
            crane + "max_speed_mps: expected an array of 3 numbers > 0, got array [0.5,0.0,0.2]");
  EXPECT_EQ(attribute_error(cell, "crane", [](const AttributeReader& r) { r.number("rated_load_kg"); }),
            crane + "rated_load_kg: expected a number, got string \"heavy\"");
  EXPECT_EQ(attribute_error(cell, "crane", [](const AttributeReader& r) { r.text("max_accel_mps2"); }),
            crane + "max_accel_mps2: expected a string, got array [0.5,0.5,0.3]");
}

// A 3x3 board of 70 mm markers (ids 30..38, unused by the cell's objects) 100 mm apart on a 0.32 m plate.
json calibration_board() {
  json items = json::array();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      items.push_back({{"id", 30 + 3 * row + col},
                       {"size_m", 0.07},
                       {"pose", {{"position_m", {0.1 * (col - 1), 0.1 * (1 - row), 0.003}}, {"rpy_deg", {0, 0, 0}}}}});
    }
  }
  return {{"mount", {{"position_m", {0.0, 0.0, 0.05}}, {"rpy_deg", {0, 0, 0}}}},
          {"size_m", {0.32, 0.32, 0.006}},
          {"markers", {{"dictionary", "DICT_4X4_50"}, {"items", items}}}};
}

TEST(CellFile, ReadsACalibrationBoardOnTheRobot) {
  json cell = shipped_cell();
  cell["entities"][index_of(cell, "robot")]["calibration_board"] = calibration_board();
  const CellFile file = cell_file_from_json(cell, "cell.json");
  const auto& board = file.require("robot", "the test").calibration_board;
  ASSERT_TRUE(board.has_value());
  EXPECT_TRUE(board->pose_tool_board.translation().isApprox(Eigen::Vector3d(0, 0, 0.05)));
  EXPECT_TRUE(board->size_m.isApprox(Eigen::Vector3d(0.32, 0.32, 0.006)));
  EXPECT_EQ(board->markers.dictionary, "DICT_4X4_50");
  ASSERT_EQ(board->markers.items.size(), 9u);
  EXPECT_EQ(board->markers.items[8].id, 38);
  EXPECT_FALSE(file.require("camera", "the test").calibration_board.has_value());
}

// Puts `board` on the robot of the shipped cell and expects the error at `path` under the board.
void expect_board_error(const json& board, const std::string& path, const std::string& expected) {
  json cell = shipped_cell();
  const std::string robot = "/entities/" + std::to_string(index_of(cell, "robot"));
  cell["entities"][index_of(cell, "robot")]["calibration_board"] = board;
  expect_error(cell, robot + "/calibration_board" + path, expected);
}

TEST(CellFile, RejectsABoardWhoseMarkersAreOffItOrTakenByObjects) {
  const json cell = shipped_cell();
  const std::string load_markers = "/entities/" + std::to_string(index_of(cell, "load")) + "/features/markers";
  json board = calibration_board();
  board["markers"]["items"][4]["id"] = 2;  // the load's marker 2; the robot comes first in the file
  json with_board = cell;
  with_board["entities"][index_of(cell, "robot")]["calibration_board"] = board;
  expect_error(with_board, load_markers + "/items/1/id",
               "unique in the cell for dictionary DICT_4X4_50, got 2, already used at /entities/" +
                   std::to_string(index_of(cell, "robot")) + "/calibration_board/markers/items/4/id");
  board = calibration_board();
  board["markers"]["items"][2]["pose"]["position_m"] = {0.13, 0.1, 0.003};  // overhangs the right edge
  expect_board_error(board, "/markers/items/2/pose", "a marker on the board's face");
  board = calibration_board();
  board["markers"]["items"][0]["pose"]["position_m"] = {-0.1, 0.1, 0.0};  // inside the plate
  expect_board_error(board, "/markers/items/0/pose", "z = thickness / 2");
  board = calibration_board();
  board["markers"]["items"][0]["pose"]["rpy_deg"] = {180, 0, 0};  // printed on the back
  expect_board_error(board, "/markers/items/0/pose", "facing +z");
  board = calibration_board();
  board["size_m"] = {0.32, 0.32, 0};
  expect_board_error(board, "/size_m", "three extents > 0 m");
  expect_board_error(json{{"size_m", {0.32, 0.32, 0.006}}}, "/mount", "the board's pose in the tool frame");
  expect_entity_error("load", "/calibration_board", calibration_board(), "a calibration board only on a device");
}

TEST(CellFile, RethrowAsGivesTheCallersErrorTypeWithTheSameText) {
  const auto read = [] { return parse_cell_file("{", "cell.json"); };
  try {
    rethrow_as<std::invalid_argument>(read);
    ADD_FAILURE() << "expected an error";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("cell.json: (document): expected valid JSON", 0), 0u) << error.what();
  }
  EXPECT_EQ(rethrow_as<std::invalid_argument>([] { return 7; }), 7);
}

TEST(MarkerDictionary, KnowsOpenCvsPredefinedDictionaries) {
  ASSERT_TRUE(marker_dictionary("DICT_4X4_50").has_value());
  EXPECT_EQ(marker_dictionary("DICT_4X4_50")->opencv_id, 0);
  EXPECT_EQ(marker_dictionary("DICT_4X4_50")->size, 50);
  EXPECT_EQ(marker_dictionary("DICT_APRILTAG_36h11")->size, 587);
  EXPECT_FALSE(marker_dictionary("DICT_9X9_50").has_value());
}

}  // namespace
}  // namespace rigger::cell
