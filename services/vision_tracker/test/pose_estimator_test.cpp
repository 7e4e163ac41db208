#include "pose_estimator.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <random>

namespace rigger::vision {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::Vector3d& axis, double angle_deg) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(angle_deg * kDeg, axis.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

class PoseEstimatorTest : public ::testing::Test {
 protected:
  PoseEstimatorTest() : estimator_(camera_, settings_) {
    // Two 8 cm markers 20 cm apart on the object's -y face (as the load's), x right, z up.
    for (const auto& [id, x] : {std::pair{1, -0.1}, {2, 0.1}}) {
      MarkerPlacement marker;
      marker.id = id;
      marker.size_m = 0.08;
      marker.pose_object_marker = pose({x, -0.15, 0.0}, Eigen::Vector3d::UnitX(), 90.0);
      layout_.markers.push_back(marker);
    }
    layout_.object_id = "load";
    // 1.5 m in front, seen 40 deg from above (as from the cell's camera).
    truth_ = pose({0.05, 0.1, 1.5}, Eigen::Vector3d::UnitX(), 50.0);
  }

  std::vector<DetectedMarker> observe(const Eigen::Isometry3d& pose_camera_object, double noise_px = 0.0,
                                      unsigned seed = 1) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, noise_px > 0.0 ? noise_px : 1.0);
    std::vector<DetectedMarker> markers;
    for (const MarkerPlacement& marker : layout_.markers) {
      DetectedMarker d;
      d.id = marker.id;
      const auto corners = marker_corners_object(marker);
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector3d p = pose_camera_object * corners[c];
        d.corners_px[c] = camera_.project(p);
        if (noise_px > 0.0) {
          d.corners_px[c] += Eigen::Vector2d(noise(rng), noise(rng));
        }
      }
      markers.push_back(d);
    }
    return markers;
  }

  CameraIntrinsics camera_ = CameraIntrinsics::pinhole(1280, 720, 1000.0, 640.0, 360.0);
  EstimatorSettings settings_;
  PoseEstimator estimator_;
  ObjectLayout layout_;
  Eigen::Isometry3d truth_;
};

TEST_F(PoseEstimatorTest, RecoversTheExactPoseFromExactCorners) {
  PoseEstimate estimate;
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth_), std::nullopt, estimate), EstimateStatus::kOk);
  EXPECT_LT((estimate.pose_camera_object.translation() - truth_.translation()).norm(), 1e-7);
  EXPECT_LT(rotation_angle_between(estimate.pose_camera_object.linear(), truth_.linear()), 1e-7);
  EXPECT_EQ(estimate.markers_used, 2);
  EXPECT_LT(estimate.reprojection_rms_px, 1e-6);
  EXPECT_FALSE(estimate.ambiguous);
  EXPECT_GT(estimate.quality, 0.99);
  EXPECT_NEAR(estimate.max_viewing_angle_rad, 40.0 * kDeg, 2.0 * kDeg);
}

// A planar layout whose plane is normal to the object's z but does not pass through its origin (markers
// on the top face of a box whose frame is its centre): OpenCV's IPPE takes such points for z = 0 ones
// unless they are given in their plane's frame.
TEST_F(PoseEstimatorTest, RecoversThePoseOfALayoutOnAPlaneOffTheObjectsOrigin) {
  layout_.markers.clear();
  for (int i = 0; i < 4; ++i) {
    MarkerPlacement marker;
    marker.id = 10 + i;
    marker.size_m = 0.07;
    marker.pose_object_marker = pose({0.1 * (i % 2) - 0.05, 0.1 * (i / 2) - 0.05, 0.05}, Eigen::Vector3d::UnitZ(), 0.0);
    layout_.markers.push_back(marker);
  }
  const Eigen::Isometry3d truth = pose({0.05, 0.1, 1.4}, Eigen::Vector3d(1, 0.3, 0), 160.0);
  PoseEstimate estimate;
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth), std::nullopt, estimate), EstimateStatus::kOk);
  EXPECT_LT((estimate.pose_camera_object.translation() - truth.translation()).norm(), 1e-7);
  EXPECT_LT(rotation_angle_between(estimate.pose_camera_object.linear(), truth.linear()), 1e-7);
  EXPECT_LT(estimate.reprojection_rms_px, 1e-6);
}

TEST_F(PoseEstimatorTest, IgnoresMarkersOfOtherLayouts) {
  std::vector<DetectedMarker> markers = observe(truth_);
  DetectedMarker stranger = markers[0];
  stranger.id = 33;
  stranger.corners_px[0] += Eigen::Vector2d(50, 50);
  markers.push_back(stranger);
  PoseEstimate estimate;
  ASSERT_EQ(estimator_.estimate(layout_, markers, std::nullopt, estimate), EstimateStatus::kOk);
  EXPECT_EQ(estimate.markers_used, 2);
  EXPECT_LT(estimate.reprojection_rms_px, 1e-6);
}

TEST_F(PoseEstimatorTest, NoMarkersOfTheLayoutIsReported) {
  PoseEstimate estimate;
  EXPECT_EQ(estimator_.estimate(layout_, {}, std::nullopt, estimate), EstimateStatus::kNoMarkers);
  std::vector<DetectedMarker> others = observe(truth_);
  others[0].id = 7;
  others[1].id = 8;
  EXPECT_EQ(estimator_.estimate(layout_, others, std::nullopt, estimate), EstimateStatus::kNoMarkers);
}

TEST_F(PoseEstimatorTest, QualityFallsWithFewerMarkersAndLargerErrors) {
  PoseEstimate both;
  PoseEstimate one;
  PoseEstimate noisy;
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth_), std::nullopt, both), EstimateStatus::kOk);
  ASSERT_EQ(estimator_.estimate(layout_, {observe(truth_)[1]}, std::nullopt, one), EstimateStatus::kOk);
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth_, 0.7), std::nullopt, noisy), EstimateStatus::kOk);
  EXPECT_EQ(one.markers_used, 1);
  EXPECT_NEAR(one.quality, both.quality * std::sqrt(0.5), 0.01);
  EXPECT_LT(noisy.quality, 0.8 * both.quality);
  EXPECT_GT(noisy.reprojection_rms_px, 0.3);
  // A single exact marker still gives the pose (IPPE on its square).
  EXPECT_LT((one.pose_camera_object.translation() - truth_.translation()).norm(), 1e-6);
}

TEST_F(PoseEstimatorTest, GrazingViewsHaveLowQuality) {
  // Turn the object so that the markers are seen at about 80 deg.
  const Eigen::Isometry3d grazing = pose({0.0, 0.0, 1.5}, Eigen::Vector3d::UnitX(), 10.0);
  PoseEstimate estimate;
  const EstimateStatus status = estimator_.estimate(layout_, observe(grazing), std::nullopt, estimate);
  EXPECT_TRUE(status == EstimateStatus::kOk || status == EstimateStatus::kLowQuality);
  EXPECT_GT(estimate.max_viewing_angle_rad, 75.0 * kDeg);
  EXPECT_LT(estimate.quality, 0.5);
}

TEST_F(PoseEstimatorTest, InconsistentCornersAreRejected) {
  std::vector<DetectedMarker> markers = observe(truth_);
  std::swap(markers[0].corners_px[0], markers[0].corners_px[2]);  // a misread orientation
  PoseEstimate estimate;
  EXPECT_EQ(estimator_.estimate(layout_, markers, std::nullopt, estimate), EstimateStatus::kReprojectionTooLarge);
  EXPECT_GT(estimate.reprojection_rms_px, settings_.max_reprojection_rms_px);
}

TEST_F(PoseEstimatorTest, CovarianceIsPositiveDefiniteAndScalesWithNoise) {
  PoseEstimate low;
  PoseEstimate high;
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth_, 0.1, 3), std::nullopt, low), EstimateStatus::kOk);
  ASSERT_EQ(estimator_.estimate(layout_, observe(truth_, 0.5, 3), std::nullopt, high), EstimateStatus::kOk);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(low.covariance_camera);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_TRUE(low.covariance_camera.isApprox(low.covariance_camera.transpose(), 1e-9));
  // Same geometry, 5x the noise: about 25x the variance.
  const double ratio = high.covariance_camera(2, 2) / low.covariance_camera(2, 2);
  EXPECT_GT(ratio, 10.0);
  EXPECT_LT(ratio, 60.0);
  // Depth (camera z) is the least certain position coordinate.
  EXPECT_GT(low.covariance_camera(2, 2), low.covariance_camera(0, 0));
}

TEST_F(PoseEstimatorTest, APriorResolvesTheMirrorAmbiguityOfOneSmallMarker) {
  // One 8 cm marker 4 m away, tilted 8 deg: its two IPPE solutions (tilted +8 and about -8 deg)
  // fit noisy corners alike. Whenever they do, the estimate follows the prior.
  MarkerPlacement marker = layout_.markers[0];
  marker.pose_object_marker = Eigen::Isometry3d::Identity();
  const ObjectLayout single{"tag", {marker}};
  const Eigen::Vector3d axis(1, 1, 0);
  const Eigen::Isometry3d truth = pose({0.0, 0.0, 4.0}, axis, 8.0);
  const Eigen::Isometry3d mirror = pose({0.0, 0.0, 4.0}, axis, -8.0);
  int ambiguous = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.3);
    DetectedMarker d;
    d.id = marker.id;
    const auto corners = marker_corners_object(marker);
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d p = truth * corners[c];
      d.corners_px[c] = Eigen::Vector2d(1000.0 * p.x() / p.z() + 640.0, 1000.0 * p.y() / p.z() + 360.0) +
                        Eigen::Vector2d(noise(rng), noise(rng));
    }
    for (const bool prior_is_truth : {true, false}) {
      const Eigen::Isometry3d& prior = prior_is_truth ? truth : mirror;
      const Eigen::Isometry3d& other = prior_is_truth ? mirror : truth;
      PoseEstimate estimate;
      estimator_.estimate(single, {d}, prior, estimate);
      if (!estimate.ambiguous) {
        continue;
      }
      ++ambiguous;
      const double to_prior = rotation_angle_between(estimate.pose_camera_object.linear(), prior.linear());
      const double to_other = rotation_angle_between(estimate.pose_camera_object.linear(), other.linear());
      EXPECT_LT(to_prior, to_other) << "seed " << seed;
      EXPECT_LE(estimate.quality, 0.5);
    }
  }
  EXPECT_GE(ambiguous, 10) << "the case should be ambiguous for most noise draws";
}

// The calibration board (3 x 3 markers of 7 cm, 10 cm apart) 1.87 m away, facing the camera or turned 13 deg off
// it: IPPE's second start refines onto the first, which is one solution, not a mirror pair. Flagged ambiguous,
// its quality was halved below what a TRACK_ONCE takes (0.5), and the camera never saw such a board.
TEST_F(PoseEstimatorTest, TwoStartsRefinedToOnePoseAreNotAmbiguous) {
  ObjectLayout board{"robot/calibration_board", {}};
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      MarkerPlacement marker;
      marker.id = 30 + 3 * row + column;
      marker.size_m = 0.07;
      marker.pose_object_marker.translation() = Eigen::Vector3d(0.1 * (column - 1), 0.1 * (1 - row), 0.003);
      board.markers.push_back(marker);
    }
  }
  for (const double turned_deg : {0.4, 13.0}) {
    const Eigen::Isometry3d truth =
        pose({0.1, -0.25, 1.87}, Eigen::Vector3d::UnitX(), 180.0) * pose({0, 0, 0}, {1, 2, 0}, turned_deg);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<DetectedMarker> markers;
    for (const MarkerPlacement& marker : board.markers) {
      DetectedMarker d;
      d.id = marker.id;
      const auto corners = marker_corners_object(marker);
      for (int c = 0; c < 4; ++c)
        d.corners_px[c] = camera_.project(truth * corners[c]) + Eigen::Vector2d(noise(rng), noise(rng));
      markers.push_back(d);
    }
    PoseEstimate estimate;
    ASSERT_EQ(estimator_.estimate(board, markers, std::nullopt, estimate), EstimateStatus::kOk) << turned_deg;
    EXPECT_FALSE(estimate.ambiguous) << turned_deg << " deg off facing";
    EXPECT_GT(estimate.quality, 0.9) << turned_deg << " deg off facing";
    EXPECT_LT(rotation_angle_between(estimate.pose_camera_object.linear(), truth.linear()), 0.2 * kDeg);
  }
}

}  // namespace
}  // namespace rigger::vision
