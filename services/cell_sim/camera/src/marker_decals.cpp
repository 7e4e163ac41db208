#include "marker_decals.hpp"

#include <opencv2/aruco/dictionary.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "render_geometry.hpp"

namespace rigger::sim::detail {
namespace {

constexpr std::array<int, 6> kTexelsPerModule = {1, 2, 4, 8, 16, 32};
// The ray that finds the face under a marker starts this far out of the face; a hit within
// kFaceTolerance_m of the plane counts as the marker's face.
constexpr double kProbeStandoff_m = 0.01;
constexpr double kFaceTolerance_m = 0.005;
// Depth test: a pixel shows the marker's plane unless the depth buffer is nearer by more than this
// (depth buffer resolution, multisample resolve at edges, the face's tessellation).
constexpr double kDepthTolerance_m = 0.004;
constexpr double kDepthToleranceFraction = 0.002;
constexpr double kMinAlbedo = 0.05;

double luma(double r, double g, double b) {
  return 0.299 * r + 0.587 * g + 0.114 * b;
}

}  // namespace

MarkerDecals::MarkerDecals(std::vector<BoxObject> objects, int dictionary, double marker_white, double marker_black)
    : objects_(std::move(objects)), white_(marker_white), black_(marker_black) {
  if (dictionary < cv::aruco::DICT_4X4_50 || dictionary > cv::aruco::DICT_APRILTAG_36h11) {
    throw std::invalid_argument("camera: unknown ArUco dictionary id " + std::to_string(dictionary));
  }
  if (!(marker_black >= 0.0 && marker_black < marker_white && marker_white <= 1.0)) {
    throw std::invalid_argument("camera: marker reflectances must satisfy 0 <= black < white <= 1");
  }
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(dictionary);
  for (const BoxObject& object : objects_) {
    std::vector<std::vector<cv::Mat>>& per_marker = textures_.emplace_back();
    for (const MarkerSpec& marker : object.markers) {
      if (marker.id < 0 || marker.id >= dict->bytesList.rows || !(marker.size_m > 0.0)) {
        throw std::invalid_argument("camera: marker " + std::to_string(marker.id) + " of '" + object.id +
                                    "' has an id outside the dictionary or a non-positive size");
      }
      per_marker.push_back(
          render_geometry::marker_texture_levels(*dict, marker.id, {kTexelsPerModule.begin(), kTexelsPerModule.end()}));
    }
  }
}

int MarkerDecals::draw(const mjModel& model, const mjData& data, const PinholeRender& render,
                       const DepthScale& depth_scale, const Eigen::Isometry3d& pose_world_camera,
                       const std::vector<ObjectPose>& poses, const cv::Mat& depth, cv::Mat& render_rgb) const {
  int drawn = 0;
  for (const ObjectPose& pose : poses) {
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      if (objects_[i].id != pose.object_id) {
        continue;
      }
      for (std::size_t m = 0; m < objects_[i].markers.size(); ++m) {
        const MarkerSpec& marker = objects_[i].markers[m];
        if (draw_one(model, data, render, depth_scale, pose_world_camera,
                     pose.pose_world_object * marker.pose_object_marker, textures_[i][m], marker.size_m, depth,
                     render_rgb)) {
          ++drawn;
        }
      }
    }
  }
  return drawn;
}

bool MarkerDecals::draw_one(const mjModel& model, const mjData& data, const PinholeRender& render,
                            const DepthScale& depth_scale, const Eigen::Isometry3d& pose_world_camera,
                            const Eigen::Isometry3d& pose_world_marker, const std::vector<cv::Mat>& levels,
                            double size_m, const cv::Mat& depth, cv::Mat& render_rgb) const {
  const Eigen::Isometry3d pose_camera_marker = pose_world_camera.inverse() * pose_world_marker;
  const Eigen::Vector3d normal_camera = pose_camera_marker.linear().col(2);
  const Eigen::Vector3d centre_camera = pose_camera_marker.translation();
  if (normal_camera.dot(centre_camera) >= 0.0) {
    return false;  // seen from behind
  }
  const int modules = levels.front().cols;  // level 0: one texel per module, quiet zone included
  const double module_m = size_m / (modules - 2);
  const double half_m = 0.5 * module_m * modules;
  std::array<Eigen::Vector2d, 4> corners;
  const std::array<Eigen::Vector2d, 4> corners_marker = {
      Eigen::Vector2d(-half_m, half_m), {half_m, half_m}, {half_m, -half_m}, {-half_m, -half_m}};
  for (std::size_t c = 0; c < 4; ++c) {
    const Eigen::Vector3d p = pose_camera_marker * Eigen::Vector3d(corners_marker[c].x(), corners_marker[c].y(), 0.0);
    if (p.z() < depth_scale.near_m) {
      return false;  // cut by the near plane: too close to be of use
    }
    corners[c] = render.project(p);
  }

  // The surface under the marker, and its albedo.
  const Eigen::Vector3d normal_world = pose_world_marker.linear().col(2);
  const Eigen::Vector3d probe = pose_world_marker.translation() + kProbeStandoff_m * normal_world;
  const Eigen::Vector3d into = -normal_world;
  int geom = -1;
  const mjtNum hit = mj_ray(&model, &data, probe.data(), into.data(), nullptr, 1, -1, &geom);
  if (geom < 0 || std::abs(hit - kProbeStandoff_m) > kFaceTolerance_m) {
    return false;
  }
  const float* rgba =
      model.geom_matid[geom] >= 0 ? model.mat_rgba + 4 * model.geom_matid[geom] : model.geom_rgba + 4 * geom;
  const double albedo = std::max(kMinAlbedo, luma(rgba[0], rgba[1], rgba[2]));

  // Render pixels the marker may cover, and the texture magnification whose texels are about one
  // pixel there: bilinear sampling then ramps each module edge over one to two pixels, centred on
  // the edge, which antialiases it without moving it.
  double min_u = corners[0].x(), max_u = min_u, min_v = corners[0].y(), max_v = min_v;
  for (const Eigen::Vector2d& c : corners) {
    min_u = std::min(min_u, c.x());
    max_u = std::max(max_u, c.x());
    min_v = std::min(min_v, c.y());
    max_v = std::max(max_v, c.y());
  }
  const int x0 = std::max(0, static_cast<int>(std::floor(min_u)) - 1);
  const int y0 = std::max(0, static_cast<int>(std::floor(min_v)) - 1);
  const int x1 = std::min(render.width_px, static_cast<int>(std::ceil(max_u)) + 2);
  const int y1 = std::min(render.height_px, static_cast<int>(std::ceil(max_v)) + 2);
  if (x0 >= x1 || y0 >= y1) {
    return false;
  }
  const double diagonal_px = std::max((corners[2] - corners[0]).norm(), (corners[3] - corners[1]).norm());
  const double module_px = diagonal_px / (std::sqrt(2.0) * modules);
  std::size_t level = 0;
  while (level + 1 < levels.size() && module_px >= kTexelsPerModule[level + 1]) {
    ++level;
  }
  const cv::Mat& texture = levels[level];
  const double texel_m = module_m / kTexelsPerModule[level];

  // Texture pixels to render pixels, exact for a plane.
  Eigen::Matrix3d camera_to_roi;
  camera_to_roi << render.f_px, 0.0, render.cx_px - x0,  //
      0.0, -render.f_px, render.cy_px - y0,              //
      0.0, 0.0, 1.0;
  const cv::Matx33d h_cv =
      render_geometry::to_cv(camera_to_roi * render_geometry::texture_to_camera(pose_camera_marker, half_m, texel_m));
  cv::warpPerspective(texture, warped_, h_cv, cv::Size(x1 - x0, y1 - y0), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(0, 0));

  // Blend where the depth buffer shows the marker's plane, at the face's rendered brightness.
  const double plane_offset = normal_camera.dot(centre_camera);  // n . p for p on the plane
  for (int y = y0; y < y1; ++y) {
    const auto* print = warped_.ptr<cv::Vec2b>(y - y0);
    const auto* buffer = depth.ptr<float>(y);
    auto* pixel = render_rgb.ptr<cv::Vec3b>(y);
    for (int x = x0; x < x1; ++x) {
      const int coverage = print[x - x0][1];
      if (coverage == 0) {
        continue;
      }
      const double z_plane = plane_offset / normal_camera.dot(render.ray(x, y));
      const double z_seen = depth_scale.z_m(buffer[x]);
      if (z_seen < z_plane - (kDepthTolerance_m + kDepthToleranceFraction * z_plane)) {
        continue;  // something stands in front of the marker
      }
      cv::Vec3b& rgb = pixel[x];
      const double light = luma(rgb[0], rgb[1], rgb[2]) / albedo;
      const double reflectance = black_ + (white_ - black_) * print[x - x0][0] / 255.0;
      const double value = std::min(255.0, light * reflectance);
      const double alpha = coverage / 255.0;
      for (int k = 0; k < 3; ++k) {
        rgb[k] = cv::saturate_cast<uchar>(rgb[k] * (1.0 - alpha) + value * alpha);
      }
    }
  }
  return true;
}

}  // namespace rigger::sim::detail
