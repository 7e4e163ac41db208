// What the camera sees of the calibration board at each pose CalibrateCamera plans (its spares too), without
// processes: the acceptance's cell (the demo cell, the board on the tool, the lens distorted, the camera 20 mm /
// 1.5° off its drawing), the arm put at each planned pose by the physics' inverse kinematics, the image rendered by
// cell_sim's MuJoCo camera from where the camera really is, and the tracker's detector and estimator on it. Every
// pose must give a pose a TRACK_ONCE takes (quality 0.5 or more) with all nine markers, within 2 mm / 0.3° of
// the truth. Each image is written to the test's log folder.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "marker_detector.hpp"
#include "pose_estimator.hpp"
#include "rigger/cell_config/calibration_board.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/cell_geometry.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/mujoco_camera.hpp"
#include "skills/camera_calibration.hpp"
#include "tracker_config.hpp"

namespace rigger {
namespace {

using nlohmann::json;
namespace calibration = skill_executor::calibration;

double deg(double rad) {
  return rad * 180.0 / M_PI;
}

// The acceptance's cell (test/integration/calibrate_camera_test.cpp): the demo cell, test/data's board on the
// robot, the lens distorted as there.
json acceptance_cell() {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
  json cell = json::parse(in);
  std::ifstream board(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
  for (json& entity : cell["entities"]) {
    if (entity["id"] == "robot") entity["calibration_board"] = json::parse(board);
    if (entity["id"] == "camera") entity["camera"]["distortion"] = {-0.04, 0.01, 0.0, 0.0, 0.0};
  }
  return cell;
}

TEST(CalibrationViewsTest, TheCameraSeesTheBoardAtEveryPlannedPose) {
  const json document = acceptance_cell();
  const std::string source = "the acceptance's cell";
  const cell::CellFile file = cell::parse_cell_file(document.dump(), source);
  const sim::CellGeometry geometry =
      sim::parse_cell_geometry(document.dump(), source, std::string(RIGGER_SOURCE_DIR) + "/deploy/cell");
  const sim::CameraScene scene = sim::parse_camera_scene(document, source);
  const Eigen::Isometry3d world_base = file.pose_root_entity("robot");
  const Eigen::Isometry3d world_camera_drawn = file.pose_root_entity("camera");
  // cell_sim's camera/pose_error of the acceptance: 20.0 mm, 1.50°.
  const Eigen::Isometry3d world_camera_true =
      world_camera_drawn *
      cell::pose_from_position_rpy_deg(Eigen::Vector3d(0.012, -0.010, 0.0125), Eigen::Vector3d(0.9, -0.85, 0.85));
  const cell::CalibrationBoard& board = *file.find("robot")->calibration_board;

  // The integrator's start: the arm's ready orientation turned 23° up, 25 cm to the base's left.
  sim::CellPhysics ready_arm(geometry);
  Eigen::Isometry3d show = Eigen::Isometry3d::Identity();
  show.linear() =
      Eigen::AngleAxisd(-23.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) * ready_arm.robot_state().pose_base_tool.linear();
  show.translation() = Eigen::Vector3d(0.65, 0.25, 0.46);

  calibration::PosePlanInput in;
  in.pose_base_tool_now = show;
  in.pose_tool_board = board.pose_tool_board;
  in.pose_base_camera = world_base.inverse() * world_camera_drawn;
  in.camera = *file.find("camera")->camera;
  in.board_size_m = std::max(board.size_m.x(), board.size_m.y());
  in.count = 15;  // the skill's 10 poses and its 5 spares
  in.tilt_rad = 15.0 * M_PI / 180.0;
  in.shift_m = 0.05;
  const std::vector<Eigen::Isometry3d> planned = calibration::plan_poses(in);
  ASSERT_GE(planned.size(), 3u);

  const vision::TrackerConfig config = vision::tracker_config_from_cell(file, "camera");
  const std::string board_id = cell::calibration_board_id("robot");
  const vision::ObjectLayout* layout = nullptr;
  for (const vision::ObjectLayout& l : config.objects)
    if (l.object_id == board_id) layout = &l;
  ASSERT_NE(layout, nullptr);
  vision::MarkerDetector detector(config.detector, config.camera);
  const vision::PoseEstimator estimator(config.camera, config.estimator);

  const std::string log_dir = std::string(RIGGER_BINARY_DIR) + "/test-logs/CalibrationViewsTest";
  std::filesystem::create_directories(log_dir);
  std::shared_ptr<const mjModel> model;
  std::unique_ptr<mjData, void (*)(mjData*)> data(nullptr, mj_deleteData);
  std::unique_ptr<sim::MujocoCamera> camera;
  sim::JointVector seed = ready_arm.robot_state().position_rad;
  int seen = 0;
  for (std::size_t i = 0; i < planned.size(); ++i) {
    const sim::IkResult ik = ready_arm.solve_ik(planned[i], &seed);
    sim::CellPhysicsOptions options;
    options.initial_joint_positions_rad = ik.position_rad;
    const sim::CellPhysics arm(geometry, options);
    seed = ik.position_rad;
    if (!model) {
      model = arm.copy_model();
      data.reset(mj_makeData(model.get()));
      camera = std::make_unique<sim::MujocoCamera>(*model, scene);
    }
    sim::KinematicState state;
    arm.copy_kinematic_state(state);
    std::copy(state.qpos.begin(), state.qpos.end(), data->qpos);
    std::copy(state.mocap_pos.begin(), state.mocap_pos.end(), data->mocap_pos);
    std::copy(state.mocap_quat.begin(), state.mocap_quat.end(), data->mocap_quat);
    mj_kinematics(model.get(), data.get());
    mj_comPos(model.get(), data.get());
    mj_camlight(model.get(), data.get());
    const Eigen::Isometry3d world_board = arm.robot_state().pose_world_tool * board.pose_tool_board;
    sim::CameraFrame frame;
    ASSERT_EQ(camera->render(*data, world_camera_true, {{board_id, world_board}}, frame, false),
              sim::RenderStatus::kOk);
    cv::imwrite(log_dir + "/pose-" + std::to_string(i + 1) + ".png", frame.image_mono8);

    const std::vector<vision::DetectedMarker> markers =
        detector.detect(frame.image_mono8, {}, config.detector.min_marker_side_px);
    vision::PoseEstimate estimate;
    const vision::EstimateStatus status = estimator.estimate(*layout, markers, std::nullopt, estimate);
    const Eigen::Isometry3d camera_board = world_camera_true.inverse() * world_board;
    const double facing = deg(std::acos(-camera_board.linear().col(2).dot(camera_board.translation().normalized())));
    const Eigen::Vector2d centre = in.camera.project(camera_board.translation());
    const bool once = status == vision::EstimateStatus::kOk && estimate.quality >= 0.5;
    EXPECT_EQ(estimate.markers_used, 9) << "pose " << i + 1;
    EXPECT_LT((estimate.pose_camera_object.translation() - camera_board.translation()).norm(), 2e-3) << i + 1;
    EXPECT_LT(Eigen::AngleAxisd(estimate.pose_camera_object.linear().transpose() * camera_board.linear()).angle(),
              0.3 * M_PI / 180.0)
        << "pose " << i + 1;
    seen += once ? 1 : 0;
    std::printf(
        "pose %zu: ik %s (%.1f mm), board %.2f m away, %.1f deg off facing, centre at (%.0f, %.0f) px; %d markers "
        "drawn, %zu detected; estimate status %d, quality %.2f, %d used, rms %.2f px, ambiguous %d, %.1f mm / "
        "%.2f deg off the truth%s\n",
        i + 1, ik.converged ? "ok" : "NOT CONVERGED", ik.position_error_m * 1e3, camera_board.translation().norm(),
        facing, centre.x(), centre.y(), frame.markers_drawn, markers.size(), static_cast<int>(status),
        estimate.quality, estimate.markers_used, estimate.reprojection_rms_px, estimate.ambiguous ? 1 : 0,
        (estimate.pose_camera_object.translation() - camera_board.translation()).norm() * 1e3,
        deg(Eigen::AngleAxisd(estimate.pose_camera_object.linear().transpose() * camera_board.linear()).angle()),
        once ? "" : "  <-- NOT SEEN");
  }
  std::printf("%d of %zu planned poses seen (images in %s)\n", seen, planned.size(), log_dir.c_str());
  EXPECT_EQ(seen, static_cast<int>(planned.size()));
}

}  // namespace
}  // namespace rigger
