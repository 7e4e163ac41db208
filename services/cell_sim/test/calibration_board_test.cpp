// The calibration board of the cell file on the robot's tool, as both renderers draw it: the physics'
// tool pose and the board's mount place it, the camera (put in front of the board's face) sees every
// marker where the mount says. Real rendering (EGL, llvmpipe on a machine without a GPU).
#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "camera_renderers.hpp"
#include "cell_sim_config.hpp"
#include "rigger/cell_config/calibration_board.hpp"

namespace rigger::cell_sim {
namespace {

using nlohmann::json;

// The demo cell with test/data's board on its robot: a 0.32 m plate 5 cm beyond the magnet's face, printed
// face out of the tool, a 3 x 3 grid of 70 mm markers (ids 30..38).
json cell_with_board() {
  std::ifstream in(default_cell_file());
  json document = json::parse(in);
  std::ifstream board(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
  for (json& entity : document["entities"])
    if (entity["id"] == "robot") entity["calibration_board"] = json::parse(board);
  return document;
}

class CalibrationBoardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const json cell = cell_with_board();
    geometry_ = sim::parse_cell_geometry(cell.dump(), "demo cell with a board", default_cell_file().parent_path());
    scene_ = sim::parse_camera_scene(cell, "demo cell with a board");
    // The arm holds the board up, face to the sky, clear of the crane's load and the tables: the tool 0.75 m
    // above the base, to its front left, z up.
    const sim::IkResult up =
        sim::CellPhysics(geometry_).solve_ik(Eigen::Translation3d(0.35, -0.35, 0.75) * Eigen::Isometry3d::Identity());
    ASSERT_TRUE(up.converged);
    sim::CellPhysicsOptions options;
    options.initial_joint_positions_rad = up.position_rad;
    physics_ = std::make_unique<sim::CellPhysics>(geometry_, options);
    ASSERT_TRUE(geometry_.robot.calibration_board.has_value());
    ASSERT_EQ(scene_.boards.size(), 1u);
    pose_world_board_ = physics_->robot_state().pose_world_tool * geometry_.robot.calibration_board->pose_tool_board;
    // The camera 0.6 m above the printed face, looking at the board's centre, rolled a little.
    scene_.pose_world_camera = pose_world_board_ * Eigen::Translation3d(0.02, -0.03, 0.6) *
                               Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
    snapshot_.poses.push_back({cell::calibration_board_id("robot"), pose_world_board_});
    physics_->copy_kinematic_state(snapshot_.state);
  }

  // Renders the snapshot and returns, by marker id, the largest offset (px) of a detected corner from the
  // corner the board's mount projects to.
  std::map<int, double> corner_errors(FrameRenderer& renderer) {
    CameraImages images;
    renderer.render(snapshot_, CameraDemand{}, images);
    const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(scene_.dictionary);
    const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
    parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(images.image_mono8, dictionary, corners, ids, parameters);
    const sim::CameraModel& c = scene_.camera;
    const cv::Matx33d k(c.fx_px, 0, c.cx_px, 0, c.fy_px, c.cy_px, 0, 0, 1);
    const Eigen::Isometry3d pose_camera_board = scene_.pose_world_camera.inverse() * pose_world_board_;
    std::map<int, double> errors;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      for (const sim::MarkerSpec& marker : scene_.boards[0].markers) {
        if (marker.id != ids[i]) continue;
        const double h = 0.5 * marker.size_m;
        std::vector<cv::Point3d> object;
        for (const auto& [x, y] : {std::pair{-h, h}, {h, h}, {h, -h}, {-h, -h}}) {
          const Eigen::Vector3d p = pose_camera_board * marker.pose_object_marker * Eigen::Vector3d(x, y, 0);
          object.emplace_back(p.x(), p.y(), p.z());
        }
        std::vector<cv::Point2d> expected;
        cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, c.distortion, expected);
        double worst = 0.0;
        for (std::size_t j = 0; j < 4; ++j) {
          worst = std::max(worst, std::hypot(corners[i][j].x - expected[j].x, corners[i][j].y - expected[j].y));
        }
        errors[ids[i]] = worst;
      }
    }
    return errors;
  }

  sim::CellGeometry geometry_;
  sim::CameraScene scene_;
  std::unique_ptr<sim::CellPhysics> physics_;
  Eigen::Isometry3d pose_world_board_ = Eigen::Isometry3d::Identity();
  CameraSnapshot snapshot_;
};

void expect_every_marker_in_place(const std::map<int, double>& errors) {
  ASSERT_EQ(errors.size(), 9u);
  double worst_px = 0.0;
  for (const auto& [id, error_px] : errors) {
    EXPECT_GE(id, 30);
    EXPECT_LE(id, 38);
    EXPECT_LT(error_px, 1.0) << "marker " << id;
    worst_px = std::max(worst_px, error_px);
  }
  std::printf("worst marker corner %.2f px from where the mount puts it\n", worst_px);
}

TEST_F(CalibrationBoardTest, MujocoDrawsEveryMarkerOfTheBoardWhereTheToolAndMountPutIt) {
  sim::MujocoCameraSettings settings;
  settings.noise_stddev = 0.0;
  const std::unique_ptr<FrameRenderer> renderer = make_mujoco_renderer(physics_->copy_model(), scene_, settings);
  expect_every_marker_in_place(corner_errors(*renderer));
}

TEST_F(CalibrationBoardTest, TheRasteriserDrawsThemToo) {
  scene_.camera.distortion.assign(scene_.camera.distortion.size(), 0.0);  // it draws through a pinhole
  sim::RenderSettings settings;
  settings.noise_stddev = 0.0;
  const std::unique_ptr<FrameRenderer> renderer = make_raster_renderer(scene_, settings);
  expect_every_marker_in_place(corner_errors(*renderer));
}

TEST_F(CalibrationBoardTest, TheBoardWeighsNothingAndTouchesNothing) {
  sim::CellGeometry without = geometry_;
  without.robot.calibration_board.reset();
  sim::CellPhysicsOptions options;
  options.initial_joint_positions_rad = physics_->robot_state().position_rad;
  sim::CellPhysics bare(without, options);
  physics_->step(std::chrono::milliseconds(200));
  bare.step(std::chrono::milliseconds(200));
  EXPECT_LT((physics_->robot_state().pose_world_tool.matrix() - bare.robot_state().pose_world_tool.matrix()).norm(),
            1e-12);
  EXPECT_LT((physics_->wrench_tool().force_n - bare.wrench_tool().force_n).norm(), 1e-9);
  EXPECT_LT((physics_->wrench_tool().torque_nm - bare.wrench_tool().torque_nm).norm(), 1e-9);
}

}  // namespace
}  // namespace rigger::cell_sim
