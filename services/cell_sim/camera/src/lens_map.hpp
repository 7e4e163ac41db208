#pragma once
// Internal: the resampling from an ideal pinhole render (square pixels, centred principal point,
// OpenGL's bottom-up rows) to the cell file's camera (intrinsics and plumb_bob distortion).

#include <opencv2/core.hpp>

#include <Eigen/Core>

#include <limits>

#include "rigger/sim/camera_scene.hpp"

namespace rigger::sim::detail {

/// The pinhole camera MuJoCo renders: focal length f_px in both axes, principal point at the image
/// centre ((width - 1) / 2, (height - 1) / 2 in pixel-centre coordinates), rows bottom-up as
/// glReadPixels returns them. A point (x, y, z) of the optical frame lands at
/// u = f x / z + cx, v = cy - f y / z.
struct PinholeRender {
  int width_px = 0;
  int height_px = 0;
  double f_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;

  /// Render pixel coordinates of an optical-frame point (z > 0).
  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const {
    return {f_px * point_camera.x() / point_camera.z() + cx_px, cy_px - f_px * point_camera.y() / point_camera.z()};
  }
  /// The optical-frame ray (z = 1) through render pixel (u, v).
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx_px) / f_px, (cy_px - v) / f_px, 1.0}; }
};

/// MuJoCo's depth buffer (window depth 0..1, 1 where nothing was drawn) as metres along the
/// optical axis, for a perspective projection between near and far (metres).
struct DepthScale {
  double near_m = 0.0;
  double far_m = 0.0;
  /// z of the optical frame at window depth `depth`; +infinity where nothing was drawn.
  double z_m(float depth) const {
    return depth >= 1.0F ? std::numeric_limits<double>::infinity()
                         : near_m * far_m / (far_m - depth * (far_m - near_m));
  }
};

/// For every pixel of the target camera, where its ray lands in the pinhole render. Built once.
class LensMap {
 public:
  /// The render's focal length is the target's larger one, lowered when the field of view would
  /// need a render over max_render_px on a side. Throws std::invalid_argument for an unusable
  /// camera (size, focal length, more than 5 distortion coefficients).
  explicit LensMap(const CameraModel& camera, int max_render_px = 4096);

  const PinholeRender& render() const { return render_; }
  /// Target pixels whose ray the distortion model cannot invert (beyond the fold of a strong
  /// distortion); they stay at the border value.
  int unmapped_pixels() const { return unmapped_; }
  /// Render column and row of each target pixel (CV_32FC1, target size; negative: unmapped).
  const cv::Mat& map_x() const { return map_x_; }
  const cv::Mat& map_y() const { return map_y_; }

  /// Bilinear resampling of an 8-bit render (any channel count) to the target image; unmapped
  /// pixels get `border`.
  void remap_image(const cv::Mat& render, cv::Mat& target, const cv::Scalar& border) const;
  /// Resamples MuJoCo's depth buffer (CV_32FC1 window depth) to the target image as metres along
  /// the optical axis (CV_32FC1, NaN where nothing was drawn or unmapped). Window depth is affine
  /// in the image over a plane, so it is interpolated bilinearly where the four render pixels
  /// around the sample agree to within 2 mm + 2 % (exact on every face, not one pixel's slope
  /// off as nearest sampling is on a tilted one); across an edge, the nearest pixel's depth.
  /// Not thread safe (a scratch image).
  void remap_depth(const cv::Mat& window_depth, const DepthScale& scale, cv::Mat& depth_m) const;

 private:
  PinholeRender render_;
  cv::Mat map_x_;     // CV_32FC1, target size: render column of each target pixel
  cv::Mat map_y_;     // CV_32FC1: render row
  cv::Mat fixed_xy_;  // the same as fixed point (cv::convertMaps) for the fast bilinear remap
  cv::Mat fixed_frac_;
  int unmapped_ = 0;
  // remap_depth's scratch image (a LensMap serves one rendering thread)
  mutable cv::Mat inverse_;  // CV_32FC1 render size: 1/z, 0 where nothing was seen
};

}  // namespace rigger::sim::detail
