// The eye-to-hand solve and the choice of its poses on exact and noisy synthetic measurements: the
// camera found within 3 mm and 0.2 degrees from 20 noisy poses, and each way a calibration must not be trusted
// refused with its code.

#include "hand_eye.hpp"

#include <gtest/gtest.h>

#include <random>

namespace rigger::vision {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::AngleAxisd& r) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = r.toRotationMatrix();
  p.translation() = t;
  return p;
}

/// A camera 1.6 m from the robot's working area, looking down at it at 40 degrees.
Eigen::Isometry3d camera_truth() {
  const Eigen::Vector3d at(0.6, 0.0, 0.4), from(0.6, -1.3, 1.4);
  const Eigen::Vector3d z = (at - from).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  Eigen::Isometry3d c = Eigen::Isometry3d::Identity();
  c.linear().col(0) = x;
  c.linear().col(1) = z.cross(x);
  c.linear().col(2) = z;
  c.translation() = from;
  return c;
}

double angle_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() / kDeg;
}

class HandEyeTest : public ::testing::Test {
 protected:
  HandEyeTest() {
    mount_ = pose({0.01, -0.02, 0.06}, Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d(1, 1, 0).normalized()));
    request_.camera = CameraIntrinsics::pinhole(1280, 720, 900.0, 640.0, 360.0);
    request_.pose_base_camera = camera_truth();
    request_.centre_base = {0.6, 0.0, 0.4};
    request_.pose_tool_board = mount_;
    for (const auto& [x, y] : {std::pair{0.12, 0.12}, {-0.12, 0.12}, {-0.12, -0.12}, {0.12, -0.12}})
      request_.board_corners.emplace_back(x, y, 0.0);
  }

  /// What the robot and the camera would report at each pose, with noise of the given size.
  std::vector<HandEyeSample> measure(const std::vector<Eigen::Isometry3d>& tools, double position_m, double angle_deg) {
    std::mt19937 rng(11);
    std::normal_distribution<double> n(0.0, 1.0);
    std::vector<HandEyeSample> samples;
    for (const Eigen::Isometry3d& tool : tools) {
      Eigen::Isometry3d board = camera_truth().inverse() * tool * mount_;
      board.translation() += position_m * Eigen::Vector3d(n(rng), n(rng), n(rng));
      board.linear() = board.linear() * Eigen::AngleAxisd(angle_deg * kDeg * n(rng),
                                                          Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized());
      samples.push_back({tool, board});
    }
    return samples;
  }

  Eigen::Isometry3d mount_;
  CalibrationPoseRequest request_;
};

TEST_F(HandEyeTest, ThePlannedPosesShowTheWholeBoardTiltedAboutSeveralAxes) {
  const std::vector<Eigen::Isometry3d> tools = plan_calibration_poses(request_);
  ASSERT_EQ(tools.size(), 12u);
  const Eigen::Matrix3d k = request_.camera.camera_matrix();
  for (const Eigen::Isometry3d& tool : tools) {
    for (const Eigen::Vector3d& corner : request_.board_corners) {
      const Eigen::Vector3d p = camera_truth().inverse() * tool * mount_ * corner;
      const Eigen::Vector3d uv = k * (p / p.z());
      EXPECT_GT(p.z(), 0.5);
      EXPECT_GE(uv.x(), 40.0);
      EXPECT_LE(uv.x(), 1240.0);
      EXPECT_GE(uv.y(), 40.0);
      EXPECT_LE(uv.y(), 680.0);
    }
  }
  EXPECT_GT(rotation_axis_spread(tools), 0.3);
}

TEST_F(HandEyeTest, PosesOutOfReachAreNotPlanned) {
  request_.reachable = [](const Eigen::Isometry3d& tool) { return tool.translation().y() < 0.0; };
  const std::vector<Eigen::Isometry3d> tools = plan_calibration_poses(request_);
  ASSERT_FALSE(tools.empty());
  for (const Eigen::Isometry3d& tool : tools) EXPECT_LT(tool.translation().y(), 0.0);
  request_.reachable = [](const Eigen::Isometry3d&) { return false; };
  EXPECT_TRUE(plan_calibration_poses(request_).empty());
}

TEST_F(HandEyeTest, ExactMeasurementsGiveTheCameraExactly) {
  HandEyeResult result;
  std::string why;
  ASSERT_EQ(solve_eye_to_hand(measure(plan_calibration_poses(request_), 0.0, 0.0), {}, result, why), HandEyeStatus::kOk)
      << why;
  EXPECT_LT((result.pose_base_camera.translation() - camera_truth().translation()).norm(), 1e-6);
  EXPECT_LT(angle_deg(result.pose_base_camera, camera_truth()), 1e-5);
  EXPECT_LT((result.pose_tool_board.translation() - mount_.translation()).norm(), 1e-6);
  EXPECT_LT(result.position_rms_m, 1e-6);
}

TEST_F(HandEyeTest, NoisyMeasurementsGiveTheCameraWithinThreeMillimetresAndAFifthOfADegree) {
  HandEyeResult result;
  std::string why;
  // A board pose from one image at 1.5 m: about 0.3 mm and 0.05 degrees; 20 poses.
  request_.count = 20;
  ASSERT_EQ(solve_eye_to_hand(measure(plan_calibration_poses(request_), 0.0003, 0.05), {}, result, why),
            HandEyeStatus::kOk)
      << why;
  const double position_mm = (result.pose_base_camera.translation() - camera_truth().translation()).norm() * 1e3;
  const double rotation_deg = angle_deg(result.pose_base_camera, camera_truth());
  std::printf("camera from 20 noisy poses: %.3f mm, %.4f deg off; residual RMS %.3f mm, %.4f deg\n", position_mm,
              rotation_deg, result.position_rms_m * 1e3, result.rotation_rms_deg);
  EXPECT_LT(position_mm, 3.0);
  EXPECT_LT(rotation_deg, 0.2);
  EXPECT_GT(result.position_rms_m, 0.0);
}

TEST_F(HandEyeTest, TooFewPosesAreRefused) {
  std::vector<Eigen::Isometry3d> tools = plan_calibration_poses(request_);
  tools.resize(4);
  HandEyeResult result;
  std::string why;
  const HandEyeStatus status = solve_eye_to_hand(measure(tools, 0.0, 0.0), {}, result, why);
  EXPECT_EQ(status, HandEyeStatus::kTooFewPoses);
  EXPECT_STREQ(hand_eye_code(status), "TOO_FEW_POSES");
  EXPECT_NE(why.find("4 poses"), std::string::npos) << why;
}

TEST_F(HandEyeTest, RotationsAboutOneAxisOnlyAreDegenerate) {
  std::vector<Eigen::Isometry3d> tools;
  const Eigen::Isometry3d first = plan_calibration_poses(request_).front();
  for (int i = 0; i < 8; ++i) {
    Eigen::Isometry3d tool = first;
    tool.linear() = first.linear() * Eigen::AngleAxisd((i - 4) * 8 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    tool.translation() += Eigen::Vector3d(0.02 * i, 0.01 * (i % 3), 0.0);
    tools.push_back(tool);
  }
  HandEyeResult result;
  std::string why;
  const HandEyeStatus status = solve_eye_to_hand(measure(tools, 0.0, 0.0), {}, result, why);
  EXPECT_EQ(status, HandEyeStatus::kDegenerate);
  EXPECT_STREQ(hand_eye_code(status), "DEGENERATE_POSES");
  EXPECT_LT(result.axis_spread, 0.01);
  EXPECT_NE(why.find("one axis"), std::string::npos) << why;
}

TEST_F(HandEyeTest, ABoardThatSlippedOnTheToolGivesAHighResidual) {
  std::vector<HandEyeSample> samples = measure(plan_calibration_poses(request_), 0.0, 0.0);
  // Half way through, the board slipped 8 mm on the tool.
  for (std::size_t i = samples.size() / 2; i < samples.size(); ++i)
    samples[i].pose_camera_board = camera_truth().inverse() * samples[i].pose_base_tool * mount_ *
                                   pose({0.008, 0.0, 0.0}, Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ()));
  HandEyeResult result;
  std::string why;
  const HandEyeStatus status = solve_eye_to_hand(samples, {}, result, why);
  EXPECT_EQ(status, HandEyeStatus::kResidualTooLarge);
  EXPECT_STREQ(hand_eye_code(status), "HIGH_RESIDUAL");
  EXPECT_GT(result.position_rms_m, 0.002);
  EXPECT_NE(why.find("mm"), std::string::npos) << why;
}

}  // namespace
}  // namespace rigger::vision
