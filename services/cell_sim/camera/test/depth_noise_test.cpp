#include "rigger/sim/depth_noise.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rigger::sim {
namespace {

const CameraModel kCamera = CameraModel::pinhole(320, 240, 300.0, 159.5, 119.5);

// The depth of a plane through (0, 0, z0) in the optical frame tilted by `tilt_rad` about the camera's x axis.
cv::Mat tilted_plane(double z0, double tilt_rad) {
  cv::Mat depth(kCamera.height_px, kCamera.width_px, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const double y = (v - kCamera.cy_px) / kCamera.fy_px;  // ray (x, y, 1) meets z = z0 + tan(tilt) * Y
    depth.at<float>(v, 0) = 0.0F;
    const double z = z0 / (1.0 - std::tan(tilt_rad) * y);
    for (int u = 0; u < depth.cols; ++u) depth.at<float>(v, u) = static_cast<float>(z);
  }
  return depth;
}

int nan_count(const cv::Mat& depth) {
  int n = 0;
  for (auto it = depth.begin<float>(); it != depth.end<float>(); ++it) n += std::isnan(*it) ? 1 : 0;
  return n;
}

TEST(DepthNoise, GrowsWithTheSquareOfTheDistance) {
  DepthNoiseSettings settings;
  settings.stddev_at_1m_m = 0.001;
  DepthNoise noise(kCamera, settings, 7);
  for (const double z : {1.0, 2.0}) {
    const cv::Mat perfect = tilted_plane(z, 0.0);
    cv::Mat depth = perfect.clone();
    noise.apply(depth);
    cv::Scalar mean, stddev;
    cv::meanStdDev(depth - perfect, mean, stddev);
    EXPECT_NEAR(stddev[0], 0.001 * z * z, 0.05 * 0.001 * z * z) << "at " << z << " m";
    EXPECT_NEAR(mean[0], 0.0, 0.0001);
    EXPECT_EQ(nan_count(depth), 0);
  }
}

TEST(DepthNoise, HolesWhereTheSurfaceIsSeenAtAGrazingAngleOnly) {
  DepthNoiseSettings settings;
  settings.grazing_deg = 70.0;
  DepthNoise noise(kCamera, settings, 1);
  cv::Mat facing = tilted_plane(1.5, 0.0);
  noise.apply(facing);
  EXPECT_EQ(nan_count(facing), 0);
  cv::Mat steep = tilted_plane(1.5, 80.0 * 3.14159265358979 / 180.0);
  // Keep only the rows where the plane is in front of the camera.
  for (auto it = steep.begin<float>(); it != steep.end<float>(); ++it) {
    if (!(*it > 0.1F && *it < 100.0F)) *it = std::numeric_limits<float>::quiet_NaN();
  }
  const int before = nan_count(steep);
  noise.apply(steep);
  // Near the centre the plane is seen about 80 degrees off its normal: gone.
  EXPECT_TRUE(std::isnan(steep.at<float>(120, 160)));
  EXPECT_GT(nan_count(steep), before + 1000);
}

TEST(DepthNoise, HolesOnBothSidesOfADepthStep) {
  DepthNoiseSettings settings;
  settings.edge_gap_m = 0.01;
  DepthNoise noise(kCamera, settings, 1);
  cv::Mat depth = tilted_plane(2.0, 0.0);
  depth(cv::Rect(100, 80, 60, 40)).setTo(1.5F);  // a box 0.5 m in front
  noise.apply(depth);
  EXPECT_TRUE(std::isnan(depth.at<float>(100, 99)));   // behind, beside the edge
  EXPECT_TRUE(std::isnan(depth.at<float>(100, 100)));  // on the box, at its edge
  EXPECT_FLOAT_EQ(depth.at<float>(100, 130), 1.5F);    // inside the box
  EXPECT_FLOAT_EQ(depth.at<float>(200, 250), 2.0F);    // the background
}

TEST(DepthNoise, RefusesBadSettingsAndLeavesOtherImagesAlone) {
  DepthNoiseSettings bad;
  bad.grazing_deg = 90.0;
  EXPECT_THROW(DepthNoise(kCamera, bad, 1), std::invalid_argument);
  bad = {};
  bad.stddev_at_1m_m = -1.0;
  EXPECT_THROW(DepthNoise(kCamera, bad, 1), std::invalid_argument);
  DepthNoiseSettings settings;
  settings.stddev_at_1m_m = 0.01;
  DepthNoise noise(kCamera, settings, 1);
  cv::Mat small(10, 10, CV_32FC1, cv::Scalar(1.0));
  noise.apply(small);  // not the camera's size
  EXPECT_EQ(cv::countNonZero(small != 1.0F), 0);
}

}  // namespace
}  // namespace rigger::sim
