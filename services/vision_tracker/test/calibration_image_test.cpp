// Eye-to-hand calibration through real images: a board of nine markers on the robot's tool, shown to
// the simulated camera at the planned poses, rendered by the simulator's own renderer (pixel noise
// as configured) and measured by the tracker. The camera's true pose is 2 cm and 1.5 degrees from
// what the cell file says; the calibration finds the true one within 3 mm and 0.2 degrees.

#include "hand_eye.hpp"
#include "sim_support.hpp"
#include "tracker.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace rigger::vision {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d pose(const Eigen::Vector3d& t, double angle_deg, const Eigen::Vector3d& axis) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(angle_deg * kDeg, axis.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

double angle_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() / kDeg;
}

/// A 0.3 m board, 1 cm thick, its frame at its centre, with a 3 x 3 grid of 7 cm markers (ids 20..28)
/// on its +z face.
sim::BoxObject board() {
  sim::BoxObject b;
  b.id = "board";
  b.size_m = {0.30, 0.30, 0.01};
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      sim::MarkerSpec m;
      m.id = 20 + 3 * row + column;
      m.size_m = 0.07;
      m.pose_object_marker.translation() = Eigen::Vector3d(0.1 * (column - 1), 0.1 * (1 - row), 0.005);
      b.markers.push_back(m);
    }
  }
  return b;
}

TEST(CalibrationImageTest, TheCameraIsFoundWithinThreeMillimetresAndAFifthOfADegreeOfItsTruePose) {
  const sim::CameraScene scene = sim::load_camera_scene(testing::deployed_cell_json_path());
  const Eigen::Isometry3d camera_truth = scene.pose_world_camera;
  // The cell file's camera: 2 cm and 1.5 degrees from the truth.
  const Eigen::Isometry3d camera_file =
      camera_truth * pose(Eigen::Vector3d(1, 1, 1).normalized() * 0.02, 1.5, {1, -2, 1});
  // The robot's base somewhere below what the camera sees at 1.4 m.
  const Eigen::Vector3d centre_world = camera_truth * Eigen::Vector3d(0, 0, 1.4);
  const Eigen::Isometry3d world_base = pose(centre_world - Eigen::Vector3d(0.5, 0.1, 0.3), 30, {0, 0, 1});
  // The board's mount on the tool as drawn, and as built (3 mm and 1 degree off).
  const Eigen::Isometry3d mount_drawn = pose({0, 0, 0.05}, 0, {0, 0, 1});
  const Eigen::Isometry3d mount_built = mount_drawn * pose({0.002, -0.002, 0.001}, 1.0, {1, 1, 0});

  const sim::BoxObject b = board();
  CalibrationPoseRequest request;
  request.camera = scene.camera;
  request.pose_base_camera = world_base.inverse() * camera_file;
  request.centre_base = world_base.inverse() * centre_world;
  request.pose_tool_board = mount_drawn;
  for (const auto& [x, y] : {std::pair{0.15, 0.15}, {-0.15, 0.15}, {-0.15, -0.15}, {0.15, -0.15}})
    request.board_corners.emplace_back(x, y, 0.005);
  request.count = 20;
  const std::vector<Eigen::Isometry3d> tools = plan_calibration_poses(request);
  ASSERT_EQ(tools.size(), 20u);

  TrackerConfig config;
  config.camera = scene.camera;
  config.pose_world_camera = camera_file;
  config.detector.dictionary = scene.dictionary;
  config.objects.push_back({"board", {}});
  for (const sim::MarkerSpec& m : b.markers) config.objects.back().markers.push_back({m.id, m.size_m, m.pose_object_marker});
  sim::CameraRenderer renderer(scene.camera, {b}, scene.dictionary, testing::render_settings(scene.camera.noise_stddev));

  std::vector<HandEyeSample> samples;
  double uncalibrated_worst_mm = 0.0;
  cv::Mat image;
  for (const Eigen::Isometry3d& tool : tools) {
    const Eigen::Isometry3d world_board = world_base * tool * mount_built;
    ASSERT_EQ(renderer.render(camera_truth, {{"board", world_board}}, image), sim::RenderStatus::kOk);
    Tracker tracker(config);
    const FrameResult frame = tracker.process(image, Stamp(std::chrono::seconds(1)));
    ASSERT_EQ(frame.objects.size(), 1u);
    const ObjectTrack& track = frame.objects.front();
    ASSERT_TRUE(track.detected) << "the board at planned pose " << samples.size() << ": " << frame.markers_detected
                                << " markers found, estimate status " << static_cast<int>(track.estimate_status);
    EXPECT_EQ(track.markers_used, 9);
    samples.push_back({tool, track.pose_camera_object});
    uncalibrated_worst_mm =
        std::max(uncalibrated_worst_mm, (track.pose_world_object.translation() - world_board.translation()).norm() * 1e3);
  }
  // Without calibration the board is placed in the world by the file's camera: centimetres off.
  EXPECT_GT(uncalibrated_worst_mm, 5.0);

  HandEyeResult result;
  std::string why;
  ASSERT_EQ(solve_eye_to_hand(samples, {}, result, why), HandEyeStatus::kOk) << why;
  const Eigen::Isometry3d camera_found = world_base * result.pose_base_camera;
  const double position_mm = (camera_found.translation() - camera_truth.translation()).norm() * 1e3;
  const double rotation_deg = angle_deg(camera_found, camera_truth);
  std::printf("calibrated camera: %.3f mm, %.4f deg from the truth (the file's: %.1f mm, %.2f deg); residual RMS %.3f "
              "mm, %.4f deg over %d poses; mount %.2f mm off; board placed up to %.1f mm off without calibration\n",
              position_mm, rotation_deg, (camera_file.translation() - camera_truth.translation()).norm() * 1e3,
              angle_deg(camera_file, camera_truth), result.position_rms_m * 1e3, result.rotation_rms_deg,
              result.samples, (result.pose_tool_board.translation() - mount_built.translation()).norm() * 1e3,
              uncalibrated_worst_mm);
  EXPECT_LT(position_mm, 3.0);
  EXPECT_LT(rotation_deg, 0.2);
}

}  // namespace
}  // namespace rigger::vision
