#include "tracker_config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <string>

namespace rigger::vision {
namespace {

using ::testing::HasSubstr;

TrackerConfig good_config() {
  TrackerConfig config;
  config.camera = CameraIntrinsics::pinhole(1280, 720, 1000.0, 640.0, 360.0);
  MarkerPlacement marker;
  marker.id = 1;
  marker.size_m = 0.08;
  config.objects.push_back({"load", {marker}});
  marker.id = 10;
  config.objects.push_back({"target", {marker}});
  return config;
}

std::string error_of(const std::function<void(TrackerConfig&)>& spoil) {
  TrackerConfig config = good_config();
  spoil(config);
  try {
    validate(config);
  } catch (const TrackerConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrackerConfig, AcceptsAGoodConfiguration) { EXPECT_NO_THROW(validate(good_config())); }

TEST(TrackerConfig, NamesTheBadCameraField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.width_px = 0; }), HasSubstr("camera.width_px"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.fy_px = -1.0; }),
              HasSubstr("camera.fy_px: expected a positive"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.cx_px = std::nan(""); }), HasSubstr("camera.cx_px"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.distortion = {0.0, 0.0, INFINITY, 0.0, 0.0}; }),
              HasSubstr("camera.distortion[2]"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.distortion = std::vector<double>(6, 0.0); }),
              HasSubstr("camera.distortion: expected none, or 4, 5, 8, 12 or 14 coefficients (OpenCV's order), not 6"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.pose_world_camera.linear() *= 2.0; }), HasSubstr("pose_world_camera"));
}

TEST(TrackerConfig, NamesTheBadLayoutField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects.clear(); }), HasSubstr("objects: expected at least one"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].object_id = "load"; }),
              HasSubstr("objects[0].object_id: expected a unique id ('load' appears twice)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers.clear(); }), HasSubstr("objects[1].markers"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].size_m = 0.0; }),
              HasSubstr("objects[1].markers[0].size_m: expected a positive size"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].id = 50; }),
              HasSubstr("objects[1].markers[0].id: expected an id in [0, 50)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].id = 1; }), HasSubstr("1 is also on 'load'"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[0].markers[0].pose_object_marker.translation().x() = NAN; }),
              HasSubstr("objects[0].markers[0].pose_object_marker"));
}

TEST(TrackerConfig, NamesTheBadTuningField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.detector.dictionary = 99; }), HasSubstr("detector.dictionary"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.detector.reacquire_every_n_frames = 0; }),
              HasSubstr("detector.reacquire_every_n_frames"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.estimator.grazing_viewing_angle_deg = 30.0; }),
              HasSubstr("good_viewing_angle_deg"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.filter.position_gain = 0.0; }), HasSubstr("filter.position_gain"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.filter.velocity_gain = 2.7; }),
              HasSubstr("filter.velocity_gain: expected a value in [0, 4 - 2 * position_gain)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.lost_after = std::chrono::milliseconds(-1); }),
              HasSubstr("lost_after"));
}

nlohmann::json deployed_cell() {
  std::ifstream file(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
  return nlohmann::json::parse(file);
}

std::string cell_error_of(const nlohmann::json& cell, const std::string& camera_id = "camera") {
  try {
    tracker_config_from_cell(cell::cell_file_from_json(cell, "cell.json"), camera_id);
  } catch (const cell::CellFileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrackerConfigFromCell, TakesTheCameraAndEveryMarkerLayout) {
  const TrackerConfig config = tracker_config_from_cell(cell::cell_file_from_json(deployed_cell(), "cell.json"), "camera");
  EXPECT_EQ(config.camera.width_px, 1280);
  EXPECT_DOUBLE_EQ(config.camera.fx_px, 1000.0);
  EXPECT_TRUE(config.pose_world_camera.translation().isApprox(Eigen::Vector3d(5.1, 2.0, 1.6)));
  EXPECT_EQ(config.detector.dictionary, 0);  // DICT_4X4_50
  ASSERT_EQ(config.objects.size(), 3u);      // load, target, and the part Pick and Place move (its table has none)
  EXPECT_EQ(config.objects[0].object_id, "load");
  ASSERT_EQ(config.objects[1].markers.size(), 2u);
  EXPECT_EQ(config.objects[1].markers[1].id, 11);
  EXPECT_DOUBLE_EQ(config.objects[1].markers[1].size_m, 0.10);
  EXPECT_EQ(config.objects[2].object_id, "part");
  ASSERT_EQ(config.objects[2].markers.size(), 2u);
  EXPECT_EQ(config.objects[2].markers[0].id, 20);
  EXPECT_EQ(config.objects[2].markers[1].id, 21);
  EXPECT_NO_THROW(validate(config));
}

TEST(TrackerConfigFromCell, NamesWhatItCannotUse) {
  EXPECT_THAT(cell_error_of(deployed_cell(), "robot"), HasSubstr("cell.json: /entities/2/camera: expected the intrinsics"));
  EXPECT_THAT(cell_error_of(deployed_cell(), "eye"), HasSubstr("/entities: expected an entity with id \"eye\""));
  nlohmann::json cell = deployed_cell();
  cell["entities"][6]["features"]["markers"]["dictionary"] = "DICT_5X5_50";
  EXPECT_THAT(cell_error_of(cell), HasSubstr("/entities/6/features/markers/dictionary: expected the dictionary of "
                                             "every other layout (DICT_4X4_50)"));
}

nlohmann::json calibration_board() {
  std::ifstream file(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
  return nlohmann::json::parse(file);
}

// The board on the robot's tool is measured like an object, under its own id, after the objects.
TEST(TrackerConfigFromCell, TakesTheCalibrationBoardOnTheRobotsTool) {
  nlohmann::json cell = deployed_cell();
  cell["entities"][2]["calibration_board"] = calibration_board();
  const TrackerConfig config = tracker_config_from_cell(cell::cell_file_from_json(cell, "cell.json"), "camera");
  ASSERT_EQ(config.objects.size(), 4u);
  EXPECT_EQ(config.objects[3].object_id, "robot/calibration_board");
  ASSERT_EQ(config.objects[3].markers.size(), 9u);
  EXPECT_EQ(config.objects[3].markers[8].id, 38);
  EXPECT_TRUE(
      config.objects[3].markers[8].pose_object_marker.translation().isApprox(Eigen::Vector3d(0.1, -0.1, 0.003)));
  EXPECT_NO_THROW(validate(config));
  cell["entities"][2]["calibration_board"]["markers"]["dictionary"] = "DICT_5X5_50";
  EXPECT_THAT(cell_error_of(cell), HasSubstr("/entities/2/calibration_board/markers/dictionary: expected the "
                                             "dictionary of every other layout (DICT_4X4_50)"));
}

// Every count the cell file accepts (OpenCV's) reaches the detector: a calibration with the rational model
// (8 coefficients) or the thin-prism and tilt terms (12, 14) is used as it is, not refused.
TEST(TrackerConfigFromCell, TakesEveryDistortionModelTheCellFileAccepts) {
  for (const std::size_t n : {4u, 5u, 8u, 12u, 14u}) {
    nlohmann::json cell = deployed_cell();
    std::vector<double> d(n, 0.0);
    d[0] = -0.1;
    d[n - 1] = 0.001 * static_cast<double>(n);
    cell["entities"][4]["camera"]["distortion"] = d;
    const TrackerConfig config = tracker_config_from_cell(cell::cell_file_from_json(cell, "cell.json"), "camera");
    EXPECT_EQ(config.camera.distortion, d) << n;
    EXPECT_NO_THROW(validate(config)) << n;
  }
}

}  // namespace
}  // namespace rigger::vision
