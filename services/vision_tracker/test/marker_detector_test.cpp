#include "marker_detector.hpp"
#include "sim_support.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <algorithm>

namespace rigger::vision {
namespace {

/// Corners from the edge-area windows, as the detector runs them: twice, the second pass centred
/// on the first fit.
void refine_by_edge_areas(const cv::Mat& image, std::array<Eigen::Vector2d, 4>& corners, int marker_id) {
  std::array<std::vector<Eigen::Vector2d>, 4> edges;
  for (int pass = 0; pass < 2; ++pass) {
    ASSERT_TRUE(sample_marker_edges(image, corners, 6, edges)) << "marker " << marker_id;
    ASSERT_TRUE(corners_from_edges(edges, corners)) << "marker " << marker_id;
  }
}

class MarkerDetectorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = sim::load_camera_scene(testing::cell_json_path());
    config_ = testing::tracker_config_from_file(testing::cell_json_path());
    poses_ = testing::both_visible_poses(scene_);
  }

  cv::Mat render(double noise, const std::vector<sim::ObjectPose>& poses) const {
    sim::CameraRenderer renderer(scene_, testing::render_settings(noise));
    cv::Mat image;
    renderer.render(scene_.pose_world_camera, poses, image);
    return image;
  }

  std::vector<sim::MarkerView> truth() const {
    return sim::CameraRenderer(scene_).marker_views(scene_.pose_world_camera, poses_);
  }

  const sim::MarkerView& view_of(const std::vector<sim::MarkerView>& views, int id) const {
    return *std::find_if(views.begin(), views.end(), [&](const sim::MarkerView& v) { return v.marker_id == id; });
  }

  sim::CameraScene scene_;
  TrackerConfig config_;
  std::vector<sim::ObjectPose> poses_;
};

TEST_F(MarkerDetectorTest, FindsEveryMarkerWithCornersWithinAFewHundredthsOfAPixel) {
  MarkerDetector detector(config_.detector, config_.camera);
  const std::vector<DetectedMarker> found = detector.detect(render(2.0, poses_), {}, 24.0);
  ASSERT_EQ(found.size(), 4u);
  const std::vector<sim::MarkerView> views = truth();
  double worst = 0.0;
  for (const DetectedMarker& marker : found) {
    EXPECT_TRUE(marker.edge_refined) << marker.id;
    const sim::MarkerView& view = view_of(views, marker.id);
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, (marker.corners_px[c] - view.corners_px[c]).norm());
    }
  }
  EXPECT_LT(worst, 0.15);
  EXPECT_EQ(found[0].id, 1);  // sorted by id
  EXPECT_EQ(found[3].id, 11);
}

TEST_F(MarkerDetectorTest, EdgeAreasGiveExactCornersOnACleanImage) {
  const cv::Mat image = render(0.0, poses_);
  for (const sim::MarkerView& view : truth()) {
    std::array<Eigen::Vector2d, 4> corners = view.corners_px;
    for (Eigen::Vector2d& c : corners) {
      c += Eigen::Vector2d(0.4, -0.3);  // a corner-window estimate's typical error
    }
    refine_by_edge_areas(image, corners, view.marker_id);
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((corners[c] - view.corners_px[c]).norm(), 0.03) << "marker " << view.marker_id << " corner " << c;
    }
  }
}

TEST_F(MarkerDetectorTest, CoarseEdgeSearchRecoversFromCornersPixelsOff) {
  const cv::Mat image = render(2.0, poses_);
  for (const sim::MarkerView& view : truth()) {
    std::array<Eigen::Vector2d, 4> corners = view.corners_px;
    // Grown by 2 px on every side, as ArUco3's pyramid refinement leaves small markers.
    const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    for (Eigen::Vector2d& c : corners) {
      c += 2.0 * (c - centre).normalized();
    }
    std::array<std::vector<Eigen::Vector2d>, 4> edges;
    // The steepest-step search gets within reach of the area windows (it locks to pixels a little)...
    ASSERT_TRUE(locate_marker_edges(image, corners, 6, edges)) << view.marker_id;
    ASSERT_TRUE(corners_from_edges(edges, corners));
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((corners[c] - view.corners_px[c]).norm(), 1.0) << "marker " << view.marker_id << " corner " << c;
    }
    // ...which then finish the job.
    refine_by_edge_areas(image, corners, view.marker_id);
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((corners[c] - view.corners_px[c]).norm(), 0.15) << "marker " << view.marker_id << " corner " << c;
    }
  }
}

TEST_F(MarkerDetectorTest, TooSmallOrFlatMarkersAreNotEdgeFitted) {
  const cv::Mat image = render(0.0, poses_);
  std::array<std::vector<Eigen::Vector2d>, 4> edges;
  // A 9 px square: modules of 1.5 px leave no room for a window.
  const std::array<Eigen::Vector2d, 4> tiny = {Eigen::Vector2d(100, 100), Eigen::Vector2d(109, 100),
                                               Eigen::Vector2d(109, 109), Eigen::Vector2d(100, 109)};
  EXPECT_FALSE(sample_marker_edges(image, tiny, 6, edges));
  // A large square on the uniform background: no contrast, no edge.
  const std::array<Eigen::Vector2d, 4> flat = {Eigen::Vector2d(50, 50), Eigen::Vector2d(150, 50),
                                               Eigen::Vector2d(150, 150), Eigen::Vector2d(50, 150)};
  EXPECT_FALSE(sample_marker_edges(image, flat, 6, edges));
  EXPECT_FALSE(locate_marker_edges(image, flat, 6, edges));
  // Too few points on an edge.
  std::array<std::vector<Eigen::Vector2d>, 4> sparse;
  std::array<Eigen::Vector2d, 4> corners;
  EXPECT_FALSE(corners_from_edges(sparse, corners));
}

TEST_F(MarkerDetectorTest, RegionsRestrictTheSearchAndAgreeWithTheFullFrame) {
  const cv::Mat image = render(2.0, poses_);
  MarkerDetector detector(config_.detector, config_.camera);
  const std::vector<DetectedMarker> full = detector.detect(image, {}, 24.0);
  const std::vector<sim::MarkerView> views = truth();
  const sim::MarkerView& load_left = view_of(views, 1);
  const cv::Rect around_load(static_cast<int>(load_left.corners_px[0].x()) - 40,
                             static_cast<int>(load_left.corners_px[0].y()) - 40, 320, 140);
  const std::vector<DetectedMarker> in_region = detector.detect(image, {around_load}, 30.0);
  ASSERT_EQ(in_region.size(), 2u);
  EXPECT_EQ(in_region[0].id, 1);
  EXPECT_EQ(in_region[1].id, 2);
  for (std::size_t m = 0; m < 2; ++m) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((in_region[m].corners_px[c] - full[m].corners_px[c]).norm(), 0.02);
    }
  }
  // Regions reaching outside the image are clipped; slivers are skipped.
  EXPECT_NO_THROW(detector.detect(image, {cv::Rect(-100, -100, 300, 300), cv::Rect(1270, 700, 100, 100)}, 24.0));
  EXPECT_TRUE(detector.detect(image, {cv::Rect(0, 0, 8, 8)}, 24.0).empty());
}

TEST_F(MarkerDetectorTest, AnIdSeenTwiceIsDropped) {
  std::vector<sim::ObjectPose> twice = poses_;
  sim::ObjectPose copy = poses_[0];
  copy.pose_world_object.translation().x() += 0.5;
  twice.push_back(copy);
  MarkerDetector detector(config_.detector, config_.camera);
  const std::vector<DetectedMarker> found = detector.detect(render(2.0, twice), {}, 24.0);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].id, 10);
  EXPECT_EQ(found[1].id, 11);
}

// The corners come out as cv::undistortPoints puts them, for plumb_bob (5 coefficients) and for the
// rational model (8: k4..k6 in the denominator), the two models camera calibrations give.
TEST_F(MarkerDetectorTest, LensDistortionIsTakenOutOfTheCorners) {
  const cv::Mat image = render(0.0, poses_);
  MarkerDetector pinhole(config_.detector, config_.camera);
  const std::vector<DetectedMarker> raw = pinhole.detect(image, {}, 24.0);
  ASSERT_FALSE(raw.empty());
  for (const std::vector<double>& model : {std::vector<double>{-0.25, 0.05, 0.001, -0.001, 0.0},
                                           std::vector<double>{-0.1, 0.01, 0.001, -0.001, 0.0, 0.15, 0.0, 0.0}}) {
    CameraIntrinsics distorted = config_.camera;
    distorted.distortion = model;
    MarkerDetector with_distortion(config_.detector, distorted);
    const std::vector<DetectedMarker> corrected = with_distortion.detect(image, {}, 24.0);
    ASSERT_EQ(raw.size(), corrected.size()) << model.size() << " coefficients";
    const cv::Mat k = (cv::Mat_<double>(3, 3) << 1000, 0, 640, 0, 1000, 360, 0, 0, 1);
    for (std::size_t m = 0; m < raw.size(); ++m) {
      std::vector<cv::Point2f> points;
      for (const Eigen::Vector2d& c : raw[m].corners_px) {
        points.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
      }
      std::vector<cv::Point2f> expected;
      cv::undistortPoints(points, expected, k, model, cv::noArray(), k);
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector2d e(expected[c].x, expected[c].y);
        EXPECT_GT((raw[m].corners_px[c] - e).norm(), 0.05) << "the distortion must matter for the test";
        EXPECT_LT((corrected[m].corners_px[c] - e).norm(), 0.05)
            << model.size() << " coefficients, marker " << raw[m].id << " corner " << c;
      }
    }
  }
}

TEST_F(MarkerDetectorTest, AnImageWithoutMarkersGivesNothing) {
  MarkerDetector detector(config_.detector, config_.camera);
  const cv::Mat blank(720, 1280, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(detector.detect(blank, {}, 24.0).empty());
  DetectorSettings bad = config_.detector;
  bad.dictionary = -3;
  EXPECT_THROW(MarkerDetector(bad, config_.camera), TrackerConfigError);
}

}  // namespace
}  // namespace rigger::vision
