#include "rigger/sim/camera_scene.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/aruco/dictionary.hpp>

#include <cmath>
#include <fstream>
#include <string>

namespace rigger::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

// A frozen copy of the cell file: these tests check the renderer against hand-derived numbers for
// that geometry, which must not change when the deployment moves its camera.
const std::string kCellJson = std::string(RIGGER_SOURCE_DIR) + "/services/cell_sim/camera/test/data/camera_test_cell.json";

json load_cell_json() {
  std::ifstream in(kCellJson);
  return json::parse(in);
}

/// Index of the entity with this id in the cell file's entities array.
std::size_t entity_index(const json& cell, const std::string& id) {
  for (std::size_t i = 0; i < cell["entities"].size(); ++i) {
    if (cell["entities"][i]["id"] == id) {
      return i;
    }
  }
  throw std::runtime_error("no entity " + id);
}

std::string parse_error(const json& cell) {
  try {
    parse_camera_scene(cell, "cell.json");
  } catch (const CameraSceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PoseFromRpy, AppliesYawPitchRollInThatOrder) {
  // R = Rz(90) Ry(0) Rx(90): x -> y, y -> z, z -> x.
  const Eigen::Isometry3d pose = pose_from_rpy_deg({1, 2, 3}, {90, 0, 90});
  EXPECT_TRUE((pose.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((pose.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_TRUE((pose.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(CameraScene, LoadsTheSimulatedCell) {
  const CameraScene scene = load_camera_scene(kCellJson);
  EXPECT_EQ(scene.camera.width_px, 1280);
  EXPECT_EQ(scene.camera.height_px, 720);
  EXPECT_DOUBLE_EQ(scene.camera.fx_px, 1000.0);
  EXPECT_DOUBLE_EQ(scene.camera.cy_px, 360.0);
  EXPECT_DOUBLE_EQ(scene.camera.noise_stddev, 2.0);
  EXPECT_EQ(scene.dictionary, cv::aruco::DICT_4X4_50);
  EXPECT_TRUE(scene.pose_world_camera.translation().isApprox(Eigen::Vector3d(3.55, 0.6, 2.2)));
  // rpy (-130, 0, 0): the optical axis looks along +y and down.
  const Eigen::Vector3d optical_axis = scene.pose_world_camera.linear().col(2);
  EXPECT_NEAR(optical_axis.y(), std::sin(130.0 * M_PI / 180.0), 1e-12);
  EXPECT_LT(optical_axis.z(), 0.0);

  ASSERT_EQ(scene.objects.size(), 2u);
  const BoxObject& load = scene.objects[0];
  const BoxObject& target = scene.objects[1];
  EXPECT_EQ(load.id, "load");
  EXPECT_EQ(target.id, "target");
  EXPECT_TRUE(load.pose_object_box.translation().isZero());
  // The target's frame is the centre of its top face: the box centre is half its height below.
  EXPECT_TRUE(target.pose_object_box.translation().isApprox(Eigen::Vector3d(0, 0, -0.475)));
  ASSERT_EQ(load.markers.size(), 2u);
  EXPECT_EQ(load.markers[0].id, 1);
  EXPECT_DOUBLE_EQ(load.markers[0].size_m, 0.08);
  // Marker normal (z) points out of the -y face.
  EXPECT_TRUE(load.markers[0].pose_object_marker.linear().col(2).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_EQ(target.markers[1].id, 11);
  EXPECT_TRUE(target.pose_world_object.translation().isApprox(Eigen::Vector3d(3.55, 2.25, 0.95)));
}

TEST(CameraScene, ComposesParentPoses) {
  json cell = load_cell_json();
  json frame = {{"id", "bench"},
                {"kind", "frame"},
                {"parent", "world"},
                {"pose", {{"position_m", {1, 0, 0}}, {"rpy_deg", {0, 0, 90}}}}};
  cell["entities"].push_back(frame);
  cell["entities"][entity_index(cell, "target")]["parent"] = "bench";
  const CameraScene scene = parse_camera_scene(cell, "cell.json");
  // target at (3.55, 2.25, 0.95) in a frame yawed 90 deg and shifted 1 m in x.
  EXPECT_TRUE(scene.objects[1].pose_world_object.translation().isApprox(Eigen::Vector3d(1 - 2.25, 3.55, 0.95), 1e-12));
}

TEST(CameraScene, MissingFieldNamesItsPointer) {
  json cell = load_cell_json();
  const std::size_t camera = entity_index(cell, "camera");
  cell["entities"][camera]["camera"].erase("fx");
  EXPECT_THAT(parse_error(cell), HasSubstr("cell.json: /entities/" + std::to_string(camera) + "/camera/fx: missing"));
}

TEST(CameraScene, RejectsWrongTypesAndValues) {
  json cell = load_cell_json();
  const std::size_t camera = entity_index(cell, "camera");
  const std::size_t load = entity_index(cell, "load");
  json bad = cell;
  bad["entities"][camera]["camera"]["width"] = -5;
  EXPECT_THAT(parse_error(bad), HasSubstr("/camera/width: expected a positive integer"));
  bad = cell;
  bad["entities"][camera]["camera"]["fy"] = "1000";
  EXPECT_THAT(parse_error(bad), HasSubstr("/camera/fy: expected a number"));
  bad = cell;
  bad["entities"][camera]["camera"]["distortion"] = json::array({0, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("/camera/distortion: expected 5 numbers"));
  bad = cell;
  bad["entities"][load]["model"]["size_m"] = json::array({0.4, 0.0, 0.2});
  EXPECT_THAT(parse_error(bad), HasSubstr("/model/size_m/1: expected a positive length"));
  bad = cell;
  bad["entities"][load]["model"]["shape"] = "cylinder";
  EXPECT_THAT(parse_error(bad), HasSubstr("/model/shape: expected \"box\""));
  bad = cell;
  bad["entities"][load]["model"]["frame"] = "somewhere";
  EXPECT_THAT(parse_error(bad), HasSubstr("/model/frame: expected \"box centre\""));
  bad = cell;
  bad["entities"][load]["pose"]["rpy_deg"] = json::array({0, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("/pose/rpy_deg: expected an array of 3 numbers"));
}

TEST(CameraScene, RejectsBadMarkers) {
  json cell = load_cell_json();
  const std::size_t load = entity_index(cell, "load");
  const std::string items = "/entities/" + std::to_string(load) + "/features/markers";
  json bad = cell;
  bad["entities"][load]["features"]["markers"]["dictionary"] = "DICT_9X9_1";
  EXPECT_THAT(parse_error(bad), HasSubstr(items + "/dictionary: unknown ArUco dictionary"));
  bad = cell;
  bad["entities"][load]["features"]["markers"]["items"][0]["id"] = 50;
  EXPECT_THAT(parse_error(bad), HasSubstr(items + "/items/0/id: expected an integer in [0, 50)"));
  bad = cell;
  bad["entities"][load]["features"]["markers"]["items"][1]["id"] = 10;  // the target's
  EXPECT_THAT(parse_error(bad), HasSubstr("marker id 10 is used twice"));
  bad = cell;
  // Floating 5 cm in front of the face.
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["position_m"] = json::array({-0.1, -0.2, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr(items + "/items/0: marker 1 does not lie on a face of 'load'"));
  bad = cell;
  // On the face plane but facing into the box.
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["rpy_deg"] = json::array({-90, 0, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("marker 1 does not lie on a face"));
  bad = cell;
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["position_m"] = json::array({-0.18, -0.15, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("marker 1 extends beyond its face of 'load'"));
}

TEST(CameraScene, RejectsStructuralErrors) {
  json cell = load_cell_json();
  json bad = cell;
  bad["entities"][entity_index(cell, "target")]["parent"] = "nowhere";
  EXPECT_THAT(parse_error(bad), HasSubstr("parent 'nowhere' of 'target' is not an entity"));
  bad = cell;
  bad["entities"].push_back(json{{"id", "load"}, {"kind", "frame"}});
  EXPECT_THAT(parse_error(bad), HasSubstr("duplicate entity id 'load'"));
  EXPECT_THAT(parse_error(json::array()), HasSubstr("cell.json: /: expected an object"));
  EXPECT_THROW(parse_camera_scene(cell, "cell.json", "no_such_camera"), CameraSceneError);
  EXPECT_THROW(load_camera_scene("/nonexistent/cell.json"), CameraSceneError);
}

TEST(CameraScene, InvalidJsonFileNamesTheFile) {
  const std::string path = ::testing::TempDir() + "/broken_cell.json";
  std::ofstream(path) << "{ \"entities\": [ ";
  try {
    load_camera_scene(path);
    FAIL() << "expected an error";
  } catch (const CameraSceneError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ": not valid JSON"));
  }
}

}  // namespace
}  // namespace rigger::sim
