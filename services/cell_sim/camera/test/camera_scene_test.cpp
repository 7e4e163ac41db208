#include "rigger/sim/camera_scene.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/aruco/dictionary.hpp>

#include <cmath>
#include <fstream>
#include <map>
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

TEST(CameraScene, TheCellReadersDictionaryIdsAreOpenCvs) {
  for (const auto& [name, id] : std::map<std::string, int>{{"DICT_4X4_50", cv::aruco::DICT_4X4_50},
                                                           {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
                                                           {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
                                                           {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
                                                           {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
                                                           {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11}}) {
    ASSERT_TRUE(cell::marker_dictionary(name).has_value()) << name;
    EXPECT_EQ(cell::marker_dictionary(name)->opencv_id, id) << name;
    EXPECT_EQ(cell::marker_dictionary(name)->size, cv::aruco::getPredefinedDictionary(id)->bytesList.rows) << name;
  }
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

TEST(CameraScene, ErrorsNameTheFileAndTheJsonPointer) {
  json cell = load_cell_json();
  const std::size_t camera = entity_index(cell, "camera");
  cell["entities"][camera]["camera"].erase("fx");
  EXPECT_THAT(parse_error(cell), HasSubstr("cell.json: /entities/" + std::to_string(camera) +
                                           "/camera/fx: expected the focal length fx in pixels"));
}

TEST(CameraScene, RejectsWhatTheRendererCannotDraw) {
  json cell = load_cell_json();
  const std::size_t camera = entity_index(cell, "camera");
  const std::size_t load = entity_index(cell, "load");
  const std::size_t target = entity_index(cell, "target");
  json bad = cell;
  bad["entities"][camera]["camera"]["distortion"] = json::array({0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("/camera/distortion: expected 4 or 5 numbers"));
  bad = cell;
  bad["entities"][camera].erase("camera");
  EXPECT_THAT(parse_error(bad), HasSubstr("/entities/" + std::to_string(camera) + "/camera: expected the intrinsics"));
  bad = cell;
  bad["entities"][load]["model"]["frame"] = "somewhere";
  EXPECT_THAT(parse_error(bad), HasSubstr("/model/frame: expected \"box centre\""));
  bad = cell;
  bad["entities"][target]["features"]["markers"]["dictionary"] = "DICT_5X5_50";
  EXPECT_THAT(parse_error(bad), HasSubstr("/features/markers/dictionary: expected the dictionary of every other object "
                                          "(DICT_4X4_50), got \"DICT_5X5_50\""));
  EXPECT_THROW(parse_camera_scene(cell, "cell.json", "no_such_camera"), CameraSceneError);
  EXPECT_THROW(load_camera_scene("/nonexistent/cell.json"), CameraSceneError);
}

TEST(CameraScene, RejectsMarkersOffTheirFaces) {
  json cell = load_cell_json();
  const std::size_t load = entity_index(cell, "load");
  const std::string items = "/entities/" + std::to_string(load) + "/features/markers/items";
  json bad = cell;
  // Floating 5 cm in front of the face.
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["position_m"] = json::array({-0.1, -0.2, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr(items + "/0: expected marker 1 flat on a face of \"load\""));
  bad = cell;
  // On the face plane but facing into the box.
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["rpy_deg"] = json::array({-90, 0, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("got a marker off every face"));
  bad = cell;
  bad["entities"][load]["features"]["markers"]["items"][0]["pose"]["position_m"] = json::array({-0.18, -0.15, 0});
  EXPECT_THAT(parse_error(bad), HasSubstr("expected marker 1 within its face of \"load\""));
}

TEST(CameraScene, InvalidJsonFileNamesTheFile) {
  const std::string path = ::testing::TempDir() + "/broken_cell.json";
  std::ofstream(path) << "{ \"entities\": [ ";
  try {
    load_camera_scene(path);
    FAIL() << "expected an error";
  } catch (const CameraSceneError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ": (document): expected valid JSON"));
  }
}

}  // namespace
}  // namespace rigger::sim
