#include "rigger/sim/depth_noise.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rigger::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The point seen at pixel (u, v) at depth z, in the optical frame (distortion left out: over one pixel
// the rays of the undistorted and distorted models differ by far less than the pixel pitch).
cv::Vec3d point(const CameraModel& c, int u, int v, double z) {
  return {(u - c.cx_px) / c.fx_px * z, (v - c.cy_px) / c.fy_px * z, z};
}

}  // namespace

DepthNoise::DepthNoise(const CameraModel& camera, DepthNoiseSettings settings, std::uint64_t seed)
    : camera_(camera), settings_(settings), rng_(seed) {
  if (!(settings_.stddev_at_1m_m >= 0.0) || !(settings_.edge_gap_m >= 0.0) || !(settings_.grazing_deg >= 0.0) ||
      !(settings_.grazing_deg < 90.0)) {
    throw std::invalid_argument(
        "depth noise: stddev_at_1m_m and edge_gap_m must be >= 0, grazing_deg within [0, 90)");
  }
}

void DepthNoise::apply(cv::Mat& depth_m) {
  if (!settings_.any() || depth_m.type() != CV_32FC1 || depth_m.cols != camera_.width_px ||
      depth_m.rows != camera_.height_px) {
    return;
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int w = depth_m.cols;
  const int h = depth_m.rows;
  if (settings_.grazing_deg > 0.0 || settings_.edge_gap_m > 0.0) {
    holes_.create(h, w, CV_8UC1);
    holes_.setTo(0);
    const double cos_grazing = std::cos(settings_.grazing_deg * kPi / 180.0);
    const auto at = [&](int u, int v) { return static_cast<double>(depth_m.at<float>(v, u)); };
    for (int v = 1; v + 1 < h; ++v) {
      for (int u = 1; u + 1 < w; ++u) {
        const double z = at(u, v);
        if (!std::isfinite(z)) continue;
        const double right = at(u + 1, v);
        const double left = at(u - 1, v);
        const double down = at(u, v + 1);
        const double up = at(u, v - 1);
        if (settings_.edge_gap_m > 0.0) {
          const double gap = settings_.edge_gap_m;
          // A neighbour across a jump, or nothing seen beside: the pattern does not come back from here.
          if (!(std::abs(right - z) <= gap) || !(std::abs(left - z) <= gap) || !(std::abs(down - z) <= gap) ||
              !(std::abs(up - z) <= gap)) {
            holes_.at<std::uint8_t>(v, u) = 1;
            continue;
          }
        }
        if (settings_.grazing_deg > 0.0 && std::isfinite(right) && std::isfinite(left) && std::isfinite(down) &&
            std::isfinite(up)) {
          const cv::Vec3d du = point(camera_, u + 1, v, right) - point(camera_, u - 1, v, left);
          const cv::Vec3d dv = point(camera_, u, v + 1, down) - point(camera_, u, v - 1, up);
          const cv::Vec3d normal = du.cross(dv);
          const cv::Vec3d ray = point(camera_, u, v, z);
          const double norms = cv::norm(normal) * cv::norm(ray);
          if (norms > 0.0 && std::abs(normal.dot(ray)) / norms < cos_grazing) holes_.at<std::uint8_t>(v, u) = 1;
        }
      }
    }
    depth_m.setTo(nan, holes_);
  }
  if (settings_.stddev_at_1m_m > 0.0) {
    for (int v = 0; v < h; ++v) {
      auto* row = depth_m.ptr<float>(v);
      for (int u = 0; u < w; ++u) {
        const double z = row[u];
        if (!std::isfinite(z)) continue;
        row[u] = static_cast<float>(z + rng_.gaussian(settings_.stddev_at_1m_m * z * z));
      }
    }
  }
}

}  // namespace rigger::sim
