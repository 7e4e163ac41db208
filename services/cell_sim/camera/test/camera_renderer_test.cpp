#include "rigger/sim/camera_renderer.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace rigger::sim {
namespace {

// A frozen copy of the cell file: these tests check the renderer against hand-derived numbers for
// that geometry, which must not change when the deployment moves its camera.
const std::string kCellJson = std::string(RIGGER_SOURCE_DIR) + "/services/cell_sim/camera/test/data/camera_test_cell.json";

struct Detection {
  std::vector<cv::Point2f> corners;
};

/// Markers found by OpenCV's detector with subpixel corner refinement, by id.
std::map<int, Detection> detect(const cv::Mat& image, int dictionary) {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  // The target's markers have ~5 px modules: a larger window reaches the quiet zone's outer edge.
  params->cornerRefinementWinSize = 3;
  params->cornerRefinementMinAccuracy = 0.01;
  cv::aruco::detectMarkers(image, cv::aruco::getPredefinedDictionary(dictionary), corners, ids, params);
  std::map<int, Detection> found;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    found[ids[i]] = Detection{corners[i]};
  }
  return found;
}

class CameraRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = load_camera_scene(kCellJson);
    settings_.albedo = {{"load", 0.62}, {"target", 0.38}};
    settings_.noise_stddev = 0.0;
  }

  /// The scenario's poses, with the load raised 0.3 m so it does not hide the target's markers.
  std::vector<ObjectPose> both_visible() const {
    std::vector<ObjectPose> poses;
    for (const BoxObject& object : scene_.objects) {
      poses.push_back({object.id, object.pose_world_object});
    }
    poses[0].pose_world_object.translation().z() += 0.3;
    return poses;
  }

  /// A frame of both_visible() from a renderer with these settings.
  cv::Mat render_with(const RenderSettings& settings) const {
    CameraRenderer renderer(scene_, settings);
    cv::Mat image;
    renderer.render(scene_.pose_world_camera, both_visible(), image);
    return image;
  }

  /// Independent pinhole projection of a marker's printed corners (ArUco order).
  std::array<Eigen::Vector2d, 4> pinhole_corners(const MarkerSpec& marker,
                                                 const Eigen::Isometry3d& pose_world_object) const {
    const Eigen::Isometry3d pose_camera_marker =
        scene_.pose_world_camera.inverse() * pose_world_object * marker.pose_object_marker;
    Eigen::Matrix<double, 3, 4> k_rt;
    Eigen::Matrix3d k;
    k << scene_.camera.fx_px, 0, scene_.camera.cx_px, 0, scene_.camera.fy_px, scene_.camera.cy_px, 0, 0, 1;
    k_rt = k * pose_camera_marker.matrix().topRows<3>();
    const double h = 0.5 * marker.size_m;
    const Eigen::Vector4d corners[4] = {{-h, h, 0, 1}, {h, h, 0, 1}, {h, -h, 0, 1}, {-h, -h, 0, 1}};
    std::array<Eigen::Vector2d, 4> out;
    for (int c = 0; c < 4; ++c) {
      out[c] = (k_rt * corners[c]).hnormalized();
    }
    return out;
  }

  CameraScene scene_;
  RenderSettings settings_;
};

TEST_F(CameraRendererTest, ImageHasTheCameraSizeAndEncoding) {
  CameraRenderer renderer(scene_, settings_);
  cv::Mat image;
  EXPECT_EQ(renderer.render(scene_.pose_world_camera, both_visible(), image), RenderStatus::kOk);
  EXPECT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.cols, 1280);
  EXPECT_EQ(image.rows, 720);
  // Not a blank frame: the objects are drawn.
  double min_value = 0;
  double max_value = 0;
  cv::minMaxLoc(image, &min_value, &max_value);
  EXPECT_LT(min_value, 30);
  EXPECT_GT(max_value, 150);
}

TEST_F(CameraRendererTest, RenderedMarkersAreDetectedWithTheirIds) {
  settings_.noise_stddev = 2.0;
  CameraRenderer renderer(scene_, settings_);
  cv::Mat image;
  renderer.render(scene_.pose_world_camera, both_visible(), image);
  const std::map<int, Detection> found = detect(image, scene_.dictionary);
  EXPECT_EQ(found.size(), 4u);
  for (const int id : {1, 2, 10, 11}) {
    EXPECT_EQ(found.count(id), 1u) << "marker " << id;
  }
}

TEST_F(CameraRendererTest, DetectedCornersMatchThePinholeModel) {
  CameraRenderer renderer(scene_, settings_);
  const std::vector<ObjectPose> poses = both_visible();
  cv::Mat image;
  renderer.render(scene_.pose_world_camera, poses, image);
  const std::map<int, Detection> found = detect(image, scene_.dictionary);
  int checked = 0;
  double worst_px = 0.0;
  for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
    for (const MarkerSpec& marker : scene_.objects[o].markers) {
      ASSERT_EQ(found.count(marker.id), 1u) << "marker " << marker.id;
      const auto expected = pinhole_corners(marker, poses[o].pose_world_object);
      for (int c = 0; c < 4; ++c) {
        const cv::Point2f& got = found.at(marker.id).corners[c];
        const double error = (Eigen::Vector2d(got.x, got.y) - expected[c]).norm();
        worst_px = std::max(worst_px, error);
        EXPECT_LT(error, 0.5) << "marker " << marker.id << " corner " << c;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 16);
  std::cout << "worst corner error " << worst_px << " px\n";
}

TEST_F(CameraRendererTest, MarkerEdgesLieOnTheProjectedLinesToAHundredthOfAPixel) {
  // A row's sum of normalised intensities across an antialiased edge is the edge's exact crossing
  // of that row (area coverage): this checks the renderer's geometry far below the corner
  // detector's own error.
  CameraRenderer renderer(scene_, settings_);
  std::vector<ObjectPose> poses = both_visible();
  poses[0].pose_world_object.translation().x() += 0.0137;  // off any grid alignment
  cv::Mat image;
  renderer.render(scene_.pose_world_camera, poses, image);
  int rows = 0;
  for (const MarkerView& view : renderer.marker_views(scene_.pose_world_camera, poses)) {
    for (const bool left : {true, false}) {
      // Left edge: corner 0 -> 3, quiet zone (white) to its left; right edge: 1 -> 2.
      const Eigen::Vector2d a = view.corners_px[left ? 0 : 1];
      const Eigen::Vector2d b = view.corners_px[left ? 3 : 2];
      double sum_error = 0.0;
      int n = 0;
      for (int y = static_cast<int>(std::ceil(a.y() + 4)); y <= static_cast<int>(std::floor(b.y() - 4)); ++y) {
        const double x_edge = a.x() + (y - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
        const int x0 = static_cast<int>(std::floor(x_edge)) - 3;
        const int x1 = x0 + 6;
        const double white = image.at<std::uint8_t>(y, left ? x0 : x1);
        const double black = image.at<std::uint8_t>(y, left ? x1 : x0);
        double whiteness = 0.0;
        for (int x = x0 + 1; x < x1; ++x) {
          whiteness += (image.at<std::uint8_t>(y, x) - black) / (white - black);
        }
        const double measured = left ? x0 + 0.5 + whiteness : x1 - 0.5 - whiteness;
        EXPECT_LT(std::abs(measured - x_edge), 0.06) << "marker " << view.marker_id << " row " << y;
        sum_error += measured - x_edge;
        ++n;
      }
      ASSERT_GT(n, 10);
      EXPECT_LT(std::abs(sum_error / n), 0.01) << "marker " << view.marker_id << (left ? " left" : " right");
      rows += n;
    }
  }
  EXPECT_GT(rows, 200);
}

TEST_F(CameraRendererTest, MarkerViewsAgreeWithThePinholeModel) {
  const CameraRenderer renderer(scene_, settings_);
  const std::vector<ObjectPose> poses = both_visible();
  const std::vector<MarkerView> views = renderer.marker_views(scene_.pose_world_camera, poses);
  ASSERT_EQ(views.size(), 4u);
  for (const MarkerView& view : views) {
    const std::size_t o = view.object_id == "load" ? 0 : 1;
    const auto& markers = scene_.objects[o].markers;
    const auto marker =
        std::find_if(markers.begin(), markers.end(), [&](const MarkerSpec& m) { return m.id == view.marker_id; });
    ASSERT_NE(marker, markers.end());
    const auto expected = pinhole_corners(*marker, poses[o].pose_world_object);
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((view.corners_px[c] - expected[c]).norm(), 1e-9);
    }
    EXPECT_TRUE(view.front_facing);
    EXPECT_DOUBLE_EQ(view.visible_fraction, 1.0);
    EXPECT_GT(view.distance_m, 1.0);
    EXPECT_LT(view.distance_m, 2.1);
  }
}

TEST_F(CameraRendererTest, AnObjectBehindAnotherIsOccluded) {
  CameraRenderer renderer(scene_, settings_);
  // The scenario's own poses: the hanging load is between the camera and the target's markers.
  std::vector<ObjectPose> poses;
  for (const BoxObject& object : scene_.objects) {
    poses.push_back({object.id, object.pose_world_object});
  }
  cv::Mat image;
  renderer.render(scene_.pose_world_camera, poses, image);
  std::map<int, Detection> found = detect(image, scene_.dictionary);
  EXPECT_EQ(found.count(1), 1u);
  EXPECT_EQ(found.count(2), 1u);
  EXPECT_EQ(found.count(10), 0u) << "marker 10 is behind the load";
  EXPECT_EQ(found.count(11), 0u) << "marker 11 is behind the load";
  for (const MarkerView& view : renderer.marker_views(scene_.pose_world_camera, poses)) {
    EXPECT_EQ(view.visible_fraction, view.object_id == "load" ? 1.0 : 0.0) << view.marker_id;
  }
  // The pixel where marker 10's centre projects shows the load's face, in either listing order.
  const MarkerView hidden = renderer.marker_views(scene_.pose_world_camera, poses)[2];
  ASSERT_EQ(hidden.marker_id, 10);
  const Eigen::Vector2d centre = 0.5 * (hidden.corners_px[0] + hidden.corners_px[2]);
  const cv::Point pixel(static_cast<int>(std::lround(centre.x())), static_cast<int>(std::lround(centre.y())));
  cv::Mat load_only;
  renderer.render(scene_.pose_world_camera, {poses[0]}, load_only);
  EXPECT_EQ(image.at<std::uint8_t>(pixel), load_only.at<std::uint8_t>(pixel));
  cv::Mat reversed;
  renderer.render(scene_.pose_world_camera, {poses[1], poses[0]}, reversed);
  EXPECT_EQ(cv::norm(image, reversed, cv::NORM_INF), 0.0);

  // Lower the load out of the line of sight: the markers reappear.
  poses[0].pose_world_object.translation().z() += 0.3;
  renderer.render(scene_.pose_world_camera, poses, image);
  found = detect(image, scene_.dictionary);
  EXPECT_EQ(found.count(10), 1u);
  EXPECT_EQ(found.count(11), 1u);
}

TEST_F(CameraRendererTest, BackFacesAndTheirMarkersAreCulled) {
  CameraRenderer renderer(scene_, settings_);
  std::vector<ObjectPose> poses = both_visible();
  // Turn the load around: its marker face now looks away from the camera.
  poses[0].pose_world_object.linear() =
      poses[0].pose_world_object.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  cv::Mat image;
  renderer.render(scene_.pose_world_camera, poses, image);
  const std::map<int, Detection> found = detect(image, scene_.dictionary);
  EXPECT_EQ(found.count(1), 0u);
  EXPECT_EQ(found.count(2), 0u);
  EXPECT_EQ(found.count(10), 1u);
  for (const MarkerView& view : renderer.marker_views(scene_.pose_world_camera, poses)) {
    EXPECT_EQ(view.front_facing, view.object_id == "target");
  }
}

TEST_F(CameraRendererTest, NoiseHasTheConfiguredDeviation) {
  const cv::Mat b = render_with(settings_);
  settings_.noise_stddev = 2.0;
  CameraRenderer noisy(scene_, settings_);
  cv::Mat a;
  noisy.render(scene_.pose_world_camera, both_visible(), a);
  cv::Mat diff;
  cv::subtract(a, b, diff, cv::noArray(), CV_32F);
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(diff, mean, stddev);
  // Rounding to 8 bits adds ~1/sqrt(12) grey level in quadrature to the deviation, and biases the
  // clean image (not the noisy one, which dithers) by up to half a level where a flat area's level
  // sits off the integer grid.
  EXPECT_NEAR(stddev[0], 2.0, 0.1);
  EXPECT_NEAR(mean[0], 0.0, 0.2);
  // Each frame draws fresh noise.
  cv::Mat again;
  noisy.render(scene_.pose_world_camera, both_visible(), again);
  EXPECT_GT(cv::norm(a, again, cv::NORM_L1) / static_cast<double>(a.total()), 1.0);
}

TEST_F(CameraRendererTest, BlurSoftensEdges) {
  const cv::Mat a = render_with(settings_);
  settings_.blur_sigma_px = 1.5;
  const cv::Mat b = render_with(settings_);
  cv::Mat ga;
  cv::Mat gb;
  cv::Sobel(a, ga, CV_32F, 1, 0);
  cv::Sobel(b, gb, CV_32F, 1, 0);
  double max_a = 0;
  double max_b = 0;
  cv::minMaxLoc(cv::abs(ga), nullptr, &max_a);
  cv::minMaxLoc(cv::abs(gb), nullptr, &max_b);
  EXPECT_LT(max_b, 0.6 * max_a);
  EXPECT_EQ(detect(b, scene_.dictionary).size(), 4u);
}

TEST_F(CameraRendererTest, BadPosesAreReportedNotThrown) {
  CameraRenderer renderer(scene_, settings_);
  std::vector<ObjectPose> poses = both_visible();
  poses.push_back({"ghost", Eigen::Isometry3d::Identity()});
  cv::Mat image;
  EXPECT_EQ(renderer.render(scene_.pose_world_camera, poses, image), RenderStatus::kUnknownObject);
  EXPECT_EQ(detect(image, scene_.dictionary).size(), 4u) << "the known objects are still drawn";

  poses = both_visible();
  poses[1].pose_world_object.translation().x() = std::nan("");
  EXPECT_EQ(renderer.render(scene_.pose_world_camera, poses, image), RenderStatus::kInvalidPose);
  EXPECT_EQ(detect(image, scene_.dictionary).size(), 0u);
}

TEST_F(CameraRendererTest, ObjectsBehindOrAroundTheCameraDoNotBreakTheFrame) {
  CameraRenderer renderer(scene_, settings_);
  std::vector<ObjectPose> poses = both_visible();
  // The load straddling the camera centre, the target behind it.
  poses[0].pose_world_object.translation() = scene_.pose_world_camera.translation();
  poses[1].pose_world_object.translation() = scene_.pose_world_camera * Eigen::Vector3d(0.0, 0.0, -2.0);
  cv::Mat image;
  EXPECT_EQ(renderer.render(scene_.pose_world_camera, poses, image), RenderStatus::kOk);
  EXPECT_EQ(image.size(), cv::Size(1280, 720));
  EXPECT_EQ(detect(image, scene_.dictionary).size(), 0u);
}

TEST_F(CameraRendererTest, RejectsUnusableConfiguration) {
  CameraModel camera = scene_.camera;
  camera.distortion = {0.1, 0.0, 0.0, 0.0, 0.0};
  EXPECT_THROW(CameraRenderer(camera, scene_.objects, scene_.dictionary), std::invalid_argument);
  camera = scene_.camera;
  camera.width_px = 0;
  EXPECT_THROW(CameraRenderer(camera, scene_.objects, scene_.dictionary), std::invalid_argument);
  EXPECT_THROW(CameraRenderer(scene_.camera, scene_.objects, 999), std::invalid_argument);
  std::vector<BoxObject> objects = scene_.objects;
  objects[0].markers[0].pose_object_marker.translation().y() = -0.3;
  EXPECT_THROW(CameraRenderer(scene_.camera, objects, scene_.dictionary), std::invalid_argument);
  RenderSettings settings;
  settings.marker_supersampling = 0;
  EXPECT_THROW(CameraRenderer(scene_, settings), std::invalid_argument);
}

}  // namespace
}  // namespace rigger::sim
