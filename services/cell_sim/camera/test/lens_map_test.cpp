// The resampling map from MuJoCo's pinhole render to the cell file's camera, against OpenCV's own
// projection with the same coefficients.
#include "lens_map.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <vector>

namespace rigger::sim::detail {
namespace {

CameraModel distorted_camera() {
  CameraModel camera = CameraModel::pinhole(1280, 960, 1000.0, 645.0, 475.0);
  camera.fy_px = 1005.0;
  camera.distortion = {-0.2, 0.05, 0.001, -0.001, 0.0};
  return camera;
}

/// Re-projects the render ray of every `step`-th target pixel with cv::projectPoints; returns the
/// largest distance to the pixel it came from.
double worst_round_trip_px(const CameraModel& camera, const LensMap& map, int step) {
  const PinholeRender& render = map.render();
  std::vector<cv::Point3d> rays;
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < camera.height_px; v += step) {
    for (int u = 0; u < camera.width_px; u += step) {
      const float ur = map.map_x().at<float>(v, u);
      const float vr = map.map_y().at<float>(v, u);
      EXPECT_GE(ur, 0.0F) << "pixel " << u << "," << v << " unmapped";
      EXPECT_LT(ur, render.width_px - 1.0F);
      EXPECT_GE(vr, 0.0F);
      EXPECT_LT(vr, render.height_px - 1.0F);
      const Eigen::Vector3d ray = render.ray(ur, vr);
      rays.emplace_back(ray.x(), ray.y(), ray.z());
      pixels.emplace_back(u, v);
    }
  }
  const cv::Matx33d k(camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, camera.distortion, projected);
  double worst = 0.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    worst = std::max(worst, cv::norm(projected[i] - pixels[i]));
  }
  return worst;
}

TEST(LensMap, EveryDistortedPixelLooksAlongTheRayOpenCvProjectsThere) {
  const CameraModel camera = distorted_camera();
  const LensMap map(camera);
  EXPECT_EQ(map.unmapped_pixels(), 0);
  // The map is stored as float: a few thousandths of a pixel.
  EXPECT_LT(worst_round_trip_px(camera, map, 7), 0.01);
  // Barrel distortion: the pinhole render must reach further out than the image.
  EXPECT_GT(map.render().width_px, camera.width_px);
  EXPECT_GT(map.render().height_px, camera.height_px);
  EXPECT_DOUBLE_EQ(map.render().f_px, 1005.0);
}

TEST(LensMap, WithoutDistortionTheRenderIsTheImageAtTheLargerFocalLength) {
  const CameraModel camera = CameraModel::pinhole(640, 480, 500.0, 320.0, 240.0);
  const LensMap map(camera);
  EXPECT_EQ(map.unmapped_pixels(), 0);
  EXPECT_LT(worst_round_trip_px(camera, map, 3), 0.01);
  EXPECT_NEAR(map.render().width_px, 640 + 6, 2);
}

TEST(LensMap, ARenderTooLargeGetsAShorterFocalLength) {
  CameraModel camera = distorted_camera();
  const LensMap map(camera, 1024);
  EXPECT_LE(map.render().width_px, 1024);
  EXPECT_LT(map.render().f_px, 1005.0);
  EXPECT_LT(worst_round_trip_px(camera, map, 11), 0.01);
}

TEST(LensMap, RejectsMoreThanFiveCoefficientsAndBadIntrinsics) {
  CameraModel camera = distorted_camera();
  camera.distortion = {0, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_THROW(LensMap{camera}, std::invalid_argument);
  camera = distorted_camera();
  camera.fx_px = 0.0;
  EXPECT_THROW(LensMap{camera}, std::invalid_argument);
  camera = distorted_camera();
  camera.width_px = 0;
  EXPECT_THROW(LensMap{camera}, std::invalid_argument);
}

}  // namespace
}  // namespace rigger::sim::detail
