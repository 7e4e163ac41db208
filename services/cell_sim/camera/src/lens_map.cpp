#include "lens_map.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rigger::sim::detail {
namespace {

constexpr std::size_t kPlumbBob = 5;
constexpr int kNewtonIterations = 30;
// A target pixel is mapped when its undistorted ray re-distorts to within this of the pixel.
constexpr double kInverseTolerance_px = 1e-4;
// Rays steeper than this (normalised coordinate) are not rendered: the pinhole render would be huge.
constexpr double kMaxNormalised = 20.0;
// Margin of render pixels around the farthest mapped ray, for the bilinear footprint.
constexpr double kMarginPx = 2.0;
// Four depth samples around a target pixel belong to one surface when they span less than this:
// more than a face tilted to 85 degrees spans between neighbouring pixels at a normal focal length.
constexpr double kDepthEdgeAbsolute_m = 0.002;
constexpr double kDepthEdgeRelative = 0.02;

struct PlumbBob {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  /// Distorted normalised coordinates of (x, y), and the Jacobian's entries.
  void apply(double x, double y, double& xd, double& yd, std::array<double, 4>& jacobian) const {
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
    jacobian[0] = radial + 2.0 * x * x * dradial + 2.0 * p1 * y + 6.0 * p2 * x;
    jacobian[1] = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y;
    jacobian[2] = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y;
    jacobian[3] = radial + 2.0 * y * y * dradial + 6.0 * p1 * y + 2.0 * p2 * x;
  }

  /// The undistorted (x, y) whose distortion is (xd, yd), on the branch through the image centre
  /// (positive Jacobian); false when Newton's method does not reach it.
  bool invert(double xd, double yd, double tolerance, double& x, double& y) const {
    x = xd;
    y = yd;
    std::array<double, 4> j{};
    for (int i = 0; i < kNewtonIterations; ++i) {
      double fx = 0;
      double fy = 0;
      apply(x, y, fx, fy, j);
      const double ex = fx - xd;
      const double ey = fy - yd;
      const double det = j[0] * j[3] - j[1] * j[2];
      if (std::abs(ex) < tolerance && std::abs(ey) < tolerance) {
        return det > 0.0;
      }
      if (!(det > 0.0)) {
        return false;
      }
      x -= (j[3] * ex - j[1] * ey) / det;
      y -= (-j[2] * ex + j[0] * ey) / det;
      if (!(std::abs(x) < kMaxNormalised && std::abs(y) < kMaxNormalised)) {
        return false;
      }
    }
    return false;
  }
};

}  // namespace

LensMap::LensMap(const CameraModel& camera, int max_render_px) {
  if (camera.width_px <= 0 || camera.height_px <= 0 || camera.width_px > 8192 || camera.height_px > 8192) {
    throw std::invalid_argument("camera: image size must be within 1..8192 pixels, not " +
                                std::to_string(camera.width_px) + " x " + std::to_string(camera.height_px));
  }
  if (!(camera.fx_px > 0.0) || !(camera.fy_px > 0.0) || !std::isfinite(camera.fx_px) || !std::isfinite(camera.fy_px) ||
      !std::isfinite(camera.cx_px) || !std::isfinite(camera.cy_px)) {
    throw std::invalid_argument("camera: focal lengths must be positive and finite, the principal point finite");
  }
  if (camera.distortion.size() > kPlumbBob) {
    throw std::invalid_argument("camera: at most 5 distortion coefficients (k1 k2 p1 p2 k3, plumb_bob), not " +
                                std::to_string(camera.distortion.size()));
  }
  std::array<double, kPlumbBob> d{};
  for (std::size_t i = 0; i < camera.distortion.size(); ++i) {
    if (!std::isfinite(camera.distortion[i])) {
      throw std::invalid_argument("camera: distortion coefficient " + std::to_string(i) + " is not finite");
    }
    d[i] = camera.distortion[i];
  }
  const PlumbBob lens{d[0], d[1], d[2], d[3], d[4]};
  const double tolerance = kInverseTolerance_px / std::max(camera.fx_px, camera.fy_px);

  // Undistorted normalised coordinates of every target pixel (NaN: unmapped).
  const int w = camera.width_px;
  const int h = camera.height_px;
  cv::Mat normal_x(h, w, CV_64FC1);
  cv::Mat normal_y(h, w, CV_64FC1);
  double reach_x = 0.0;
  double reach_y = 0.0;
  for (int v = 0; v < h; ++v) {
    auto* nx = normal_x.ptr<double>(v);
    auto* ny = normal_y.ptr<double>(v);
    const double yd = (v - camera.cy_px) / camera.fy_px;
    for (int u = 0; u < w; ++u) {
      const double xd = (u - camera.cx_px) / camera.fx_px;
      double x = 0;
      double y = 0;
      if (lens.invert(xd, yd, tolerance, x, y)) {
        nx[u] = x;
        ny[u] = y;
        reach_x = std::max(reach_x, std::abs(x));
        reach_y = std::max(reach_y, std::abs(y));
      } else {
        nx[u] = ny[u] = std::numeric_limits<double>::quiet_NaN();
        ++unmapped_;
      }
    }
  }

  // The pinhole render: square pixels at the target's larger focal length, centred, just wide
  // enough for every mapped ray (and smaller in focal length if that would exceed the cap).
  double f = std::max(camera.fx_px, camera.fy_px);
  const auto side = [&](double reach, double focal) {
    return 2 * static_cast<int>(std::ceil(reach * focal + kMarginPx)) + 1;
  };
  const int longest = std::max(side(reach_x, f), side(reach_y, f));
  if (longest > max_render_px) {
    f *= static_cast<double>(max_render_px - 2 * kMarginPx - 3) / (longest - 2 * kMarginPx - 1);
  }
  render_.f_px = f;
  render_.width_px = side(reach_x, f);
  render_.height_px = side(reach_y, f);
  render_.cx_px = 0.5 * (render_.width_px - 1);
  render_.cy_px = 0.5 * (render_.height_px - 1);

  map_x_.create(h, w, CV_32FC1);
  map_y_.create(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    const auto* nx = normal_x.ptr<double>(v);
    const auto* ny = normal_y.ptr<double>(v);
    auto* mx = map_x_.ptr<float>(v);
    auto* my = map_y_.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      if (std::isnan(nx[u])) {
        mx[u] = my[u] = -10.0F;  // outside the render: the border value
        continue;
      }
      mx[u] = static_cast<float>(f * nx[u] + render_.cx_px);
      my[u] = static_cast<float>(render_.cy_px - f * ny[u]);
    }
  }
  cv::convertMaps(map_x_, map_y_, fixed_xy_, fixed_frac_, CV_16SC2);
}

void LensMap::remap_image(const cv::Mat& render, cv::Mat& target, const cv::Scalar& border) const {
  cv::remap(render, target, fixed_xy_, fixed_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, border);
}

void LensMap::remap_depth(const cv::Mat& window_depth, const DepthScale& scale, cv::Mat& depth_m) const {
  // Inverse depth 1/z = 1/near - d (far - near) / (near far) is affine in the window depth d, hence
  // in the image over a plane: bilinear interpolation of it is exact on every face. 0: nothing seen.
  const auto slope = static_cast<float>(-(scale.far_m - scale.near_m) / (scale.near_m * scale.far_m));
  const auto offset = static_cast<float>(1.0 / scale.near_m);
  inverse_.create(window_depth.size(), CV_32FC1);
  for (int y = 0; y < window_depth.rows; ++y) {
    const auto* d = window_depth.ptr<float>(y);
    auto* inverse = inverse_.ptr<float>(y);
    for (int x = 0; x < window_depth.cols; ++x) {
      inverse[x] = d[x] >= 1.0F ? 0.0F : offset + slope * d[x];
    }
  }

  // Bilinear within one face; where the four render pixels around the sample span an edge
  // (something not seen, or a depth range beyond what one tilted face spans between neighbouring
  // pixels), the nearest pixel's depth.
  depth_m.create(map_x_.size(), CV_32FC1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int last_x = inverse_.cols - 1;
  const int last_y = inverse_.rows - 1;
  const auto edge_absolute = static_cast<float>(kDepthEdgeAbsolute_m);
  const auto edge_relative = static_cast<float>(kDepthEdgeRelative);
  for (int v = 0; v < map_x_.rows; ++v) {
    const auto* mx = map_x_.ptr<float>(v);
    const auto* my = map_y_.ptr<float>(v);
    auto* out = depth_m.ptr<float>(v);
    for (int u = 0; u < map_x_.cols; ++u) {
      const float x = mx[u];
      const float y = my[u];
      if (!(x >= 0.0F && y >= 0.0F && x <= last_x && y <= last_y)) {
        out[u] = nan;
        continue;
      }
      const int x0 = std::min(static_cast<int>(x), last_x - 1);
      const int y0 = std::min(static_cast<int>(y), last_y - 1);
      const float fx = x - x0;
      const float fy = y - y0;
      const float* row0 = inverse_.ptr<float>(y0) + x0;
      const float* row1 = inverse_.ptr<float>(y0 + 1) + x0;
      const float i00 = row0[0];
      const float i01 = row0[1];
      const float i10 = row1[0];
      const float i11 = row1[1];
      const float lo = std::min(std::min(i00, i01), std::min(i10, i11));  // farthest
      const float hi = std::max(std::max(i00, i01), std::max(i10, i11));  // nearest
      float inverse = 0.0F;
      if (lo > 0.0F && 1.0F / lo - 1.0F / hi <= edge_absolute + edge_relative / hi) {
        const float top = i00 + fx * (i01 - i00);
        const float bottom = i10 + fx * (i11 - i10);
        inverse = top + fy * (bottom - top);
      } else {
        inverse = fy < 0.5F ? (fx < 0.5F ? i00 : i01) : (fx < 0.5F ? i10 : i11);
      }
      out[u] = inverse > 0.0F ? 1.0F / inverse : nan;
    }
  }
}

}  // namespace rigger::sim::detail
