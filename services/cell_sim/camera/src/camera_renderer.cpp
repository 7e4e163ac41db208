#include "rigger/sim/camera_renderer.hpp"

#include <opencv2/aruco/dictionary.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "render_geometry.hpp"

namespace rigger::sim {

using namespace render_geometry;

namespace {

// Supersampled area budgets (samples per polygon): keeps a close-up from costing seconds while
// leaving small, distant markers (the ones whose corners matter) at full antialiasing quality.
constexpr double kFaceSampleBudget = 4.0e6;
constexpr double kMarkerSampleBudget = 1.5e6;
// Fixed-point fraction bits for cv::fillConvexPoly vertices.
constexpr int kPolyShiftBits = 8;
// Marker textures are magnified and sampled bilinearly at each supersample: a module boundary is a
// linear ramp one texel wide centred exactly on the boundary. With the ramp about two supersamples
// wide, the area-averaged edge position varies continuously with the pose instead of snapping to
// the supersample grid (which biases axis-aligned edges by up to 1/(2s) px); a magnification per
// octave of on-screen module size keeps it so from far to near.
constexpr std::array<int, 6> kTexelsPerModule = {1, 2, 4, 8, 16, 32};
constexpr double kRampSupersamples = 2.0;

}  // namespace

CameraRenderer::CameraRenderer(CameraModel camera, std::vector<BoxObject> objects, int dictionary,
                               RenderSettings settings)
    : camera_(std::move(camera)), objects_(std::move(objects)), settings_(std::move(settings)) {
  if (camera_.width_px <= 0 || camera_.height_px <= 0 || camera_.width_px > 8192 || camera_.height_px > 8192) {
    throw std::invalid_argument("camera renderer: image size must be within 1..8192 pixels");
  }
  if (!(camera_.fx_px > 0.0) || !(camera_.fy_px > 0.0) || !std::isfinite(camera_.cx_px) ||
      !std::isfinite(camera_.cy_px)) {
    throw std::invalid_argument("camera renderer: focal lengths must be positive and the principal point finite");
  }
  for (const double d : camera_.distortion) {
    if (d != 0.0) {
      throw std::invalid_argument("camera renderer: lens distortion is not supported (expected 5 zeros)");
    }
  }
  noise_stddev_ = settings_.noise_stddev.value_or(camera_.noise_stddev);
  noise_ = PixelNoise(noise_stddev_, settings_.seed);
  if (!(noise_stddev_ >= 0.0) || !(settings_.blur_sigma_px >= 0.0)) {
    throw std::invalid_argument("camera renderer: noise_stddev and blur_sigma_px must be >= 0");
  }
  if (settings_.face_supersampling < 1 || settings_.face_supersampling > 16 || settings_.marker_supersampling < 1 ||
      settings_.marker_supersampling > 16) {
    throw std::invalid_argument("camera renderer: supersampling must be within 1..16");
  }
  if (!(settings_.ambient >= 0.0 && settings_.ambient <= 1.0) || !(settings_.light_direction_world.norm() > 0.0)) {
    throw std::invalid_argument("camera renderer: ambient must be in [0, 1] and the light direction non-zero");
  }
  settings_.light_direction_world.normalize();

  if (dictionary < cv::aruco::DICT_4X4_50 || dictionary > cv::aruco::DICT_APRILTAG_36h11) {
    throw std::invalid_argument("camera renderer: unknown ArUco dictionary id " + std::to_string(dictionary));
  }
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(dictionary);

  data_.resize(objects_.size());
  marker_textures_.resize(objects_.size());
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const BoxObject& object = objects_[i];
    ObjectData& data = data_[i];
    const auto albedo = settings_.albedo.find(object.id);
    data.albedo = albedo != settings_.albedo.end() ? albedo->second : settings_.default_albedo;
    const Eigen::Vector3d half = 0.5 * object.size_m;
    for (int axis = 0; axis < 3; ++axis) {
      for (int side = 0; side < 2; ++side) {
        const double sign = side == 0 ? -1.0 : 1.0;
        const int u = (axis + 1) % 3;
        const int v = (axis + 2) % 3;
        Face& face = data.faces[2 * axis + side];
        const double du[4] = {-1, 1, 1, -1};
        const double dv[4] = {-1, -1, 1, 1};
        for (int c = 0; c < 4; ++c) {
          Eigen::Vector3d p = Eigen::Vector3d::Zero();
          p[axis] = sign * half[axis];
          p[u] = du[c] * half[u];
          p[v] = dv[c] * half[v];
          face.corners_object[c] = object.pose_object_box * p;
        }
        face.normal_object = object.pose_object_box.linear() * (sign * Eigen::Vector3d::Unit(axis));
      }
    }
    for (std::size_t m = 0; m < object.markers.size(); ++m) {
      const MarkerSpec& marker = object.markers[m];
      if (marker.id < 0 || marker.id >= dict->bytesList.rows || !(marker.size_m > 0.0)) {
        throw std::invalid_argument("camera renderer: marker " + std::to_string(marker.id) + " of '" + object.id +
                                    "' has an id outside the dictionary or a non-positive size");
      }
      const Eigen::Vector3d normal = marker.pose_object_marker.linear().col(2);
      const Eigen::Vector3d centre = marker.pose_object_marker.translation();
      bool placed = false;
      for (Face& face : data.faces) {
        if (normal.dot(face.normal_object) > 0.999 &&
            std::abs((centre - face.corners_object[0]).dot(face.normal_object)) < 1e-3) {
          face.markers.push_back(m);
          placed = true;
          break;
        }
      }
      if (!placed) {
        throw std::invalid_argument("camera renderer: marker " + std::to_string(marker.id) + " of '" + object.id +
                                    "' does not lie on a face of its box facing outwards");
      }
      const std::vector<cv::Mat> levels =
          marker_texture_levels(*dict, marker.id, {kTexelsPerModule.begin(), kTexelsPerModule.end()});
      marker_textures_[i].push_back(levels);
    }
  }
}

namespace {
// The rasteriser draws boxes: the box objects and the calibration boards.
std::vector<BoxObject> boxes(const CameraScene& scene) {
  std::vector<BoxObject> objects = scene.objects;
  objects.insert(objects.end(), scene.boards.begin(), scene.boards.end());
  return objects;
}
}  // namespace

CameraRenderer::CameraRenderer(const CameraScene& scene, RenderSettings settings)
    : CameraRenderer(scene.camera, boxes(scene), scene.dictionary, std::move(settings)) {}

Eigen::Vector2d CameraRenderer::project(const Eigen::Vector3d& p) const {
  return camera_.project(p);
}

std::vector<std::size_t> CameraRenderer::painter_order(const std::vector<Placed>& placed) const {
  const std::size_t n = placed.size();
  std::vector<Box> boxes;
  boxes.reserve(n);
  for (const Placed& p : placed) {
    boxes.push_back(box_in_camera(objects_[p.index], p.pose_camera_object));
  }
  // before[i][j]: i must be drawn before j (j may hide i).
  std::vector<std::vector<bool>> before(n, std::vector<bool>(n, false));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const int f = front_of(boxes[i], boxes[j]);
      if (f > 0) {
        before[j][i] = true;
      } else if (f < 0) {
        before[i][j] = true;
      }
    }
  }
  std::vector<std::size_t> order;
  std::vector<bool> done(n, false);
  for (std::size_t step = 0; step < n; ++step) {
    // Among the objects nothing undrawn must precede, the farthest first; on a cycle (objects
    // that interpenetrate) the farthest of all.
    std::size_t best = n;
    bool best_free = false;
    for (std::size_t i = 0; i < n; ++i) {
      if (done[i]) {
        continue;
      }
      bool free = true;
      for (std::size_t k = 0; k < n; ++k) {
        if (!done[k] && before[k][i]) {
          free = false;
        }
      }
      const bool better = best == n || (free && !best_free) ||
                          (free == best_free && boxes[i].centre.norm() > boxes[best].centre.norm());
      if (better) {
        best = i;
        best_free = free;
      }
    }
    done[best] = true;
    order.push_back(best);
  }
  return order;
}

void CameraRenderer::draw_polygon(const std::vector<Eigen::Vector3d>& corners_camera, double radiance) {
  const std::vector<Eigen::Vector3d> clipped = clip_near(corners_camera);
  if (clipped.size() < 3) {
    return;
  }
  std::vector<Eigen::Vector2d> poly;
  poly.reserve(clipped.size());
  for (const Eigen::Vector3d& p : clipped) {
    poly.push_back(project(p));
  }
  // Clip to a frame just outside the image so fixed-point vertices cannot overflow.
  poly = clip_half_plane(poly, 0, -2.0, 1.0);
  poly = clip_half_plane(poly, 0, camera_.width_px + 1.0, -1.0);
  poly = clip_half_plane(poly, 1, -2.0, 1.0);
  poly = clip_half_plane(poly, 1, camera_.height_px + 1.0, -1.0);
  if (poly.size() < 3) {
    return;
  }
  const cv::Rect roi = pixel_bounds(poly, camera_.width_px, camera_.height_px);
  if (roi.empty()) {
    return;
  }
  const int s = supersampling_for(roi, settings_.face_supersampling, kFaceSampleBudget);
  const Eigen::Matrix3d to_ss = image_to_supersampled(roi, s);
  std::vector<cv::Point> pts;
  pts.reserve(poly.size());
  for (const Eigen::Vector2d& p : poly) {
    const Eigen::Vector3d q = to_ss * p.homogeneous();
    pts.emplace_back(static_cast<int>(std::lround(q.x() * (1 << kPolyShiftBits))),
                     static_cast<int>(std::lround(q.y() * (1 << kPolyShiftBits))));
  }
  scratch_a_.create(roi.height * s, roi.width * s, CV_8UC1);
  scratch_a_.setTo(0);
  cv::fillConvexPoly(scratch_a_, pts, cv::Scalar(255), cv::LINE_8, kPolyShiftBits);
  if (s > 1) {
    cv::resize(scratch_a_, scratch_b_, roi.size(), 0, 0, cv::INTER_AREA);
    blend_uniform(canvas_, roi, scratch_b_, radiance);
  } else {
    blend_uniform(canvas_, roi, scratch_a_, radiance);
  }
}

void CameraRenderer::draw_marker(const BoxObject& object, std::size_t marker_index,
                                 const Eigen::Isometry3d& pose_camera_object, double light) {
  const MarkerSpec& marker = object.markers[marker_index];
  const std::size_t object_index = static_cast<std::size_t>(&object - objects_.data());
  const std::vector<cv::Mat>& levels = marker_textures_[object_index][marker_index];
  const int modules_with_quiet_zone = levels.front().cols;  // level 0: one texel per module
  const double module_m = marker.size_m / (modules_with_quiet_zone - 2);
  const double half_m = 0.5 * module_m * modules_with_quiet_zone;

  const Eigen::Isometry3d pose_camera_marker = pose_camera_object * marker.pose_object_marker;
  std::vector<Eigen::Vector2d> corners;
  for (const auto& [u, v] : {std::pair{-1.0, 1.0}, {1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}}) {
    const Eigen::Vector3d p = pose_camera_marker * Eigen::Vector3d(u * half_m, v * half_m, 0.0);
    if (p.z() < kNearPlane_m) {
      return;  // a marker cut by the near plane is too close to be of use; skip it
    }
    corners.push_back(project(p));
  }
  const cv::Rect roi = pixel_bounds(corners, camera_.width_px, camera_.height_px);
  if (roi.empty()) {
    return;
  }
  const int s = supersampling_for(roi, settings_.marker_supersampling, kMarkerSampleBudget);
  const double side_px = 0.25 * ((corners[1] - corners[0]).norm() + (corners[2] - corners[1]).norm() +
                                 (corners[3] - corners[2]).norm() + (corners[0] - corners[3]).norm());
  const double wanted_texels = side_px / modules_with_quiet_zone * s / kRampSupersamples;
  std::size_t level = 0;
  while (level + 1 < kTexelsPerModule.size() && kTexelsPerModule[level + 1] <= wanted_texels * std::sqrt(2.0)) {
    ++level;
  }
  const cv::Mat& texture = levels[level];
  const double texel_m = module_m / kTexelsPerModule[level];

  Eigen::Matrix3d k;
  k << camera_.fx_px, 0, camera_.cx_px, 0, camera_.fy_px, camera_.cy_px, 0, 0, 1;
  const cv::Matx33d h_cv =
      to_cv(image_to_supersampled(roi, s) * k * texture_to_camera(pose_camera_marker, half_m, texel_m));
  // One two-channel warp: the print (0 outside) and its coverage (255 inside, 0 outside).
  const cv::Size ss_size(roi.width * s, roi.height * s);
  cv::Mat warped;
  cv::warpPerspective(texture, warped, h_cv, ss_size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0));
  cv::Mat averaged;
  if (s > 1) {
    cv::resize(warped, averaged, roi.size(), 0, 0, cv::INTER_AREA);
  } else {
    averaged = warped;
  }
  // Premultiplied: the covered fraction is black print plus (white - black) where the print is white.
  const float scale = static_cast<float>(light);
  const float black = static_cast<float>(settings_.marker_black) * scale;
  const float contrast = static_cast<float>(settings_.marker_white - settings_.marker_black) * scale;
  for (int y = 0; y < roi.height; ++y) {
    float* row = canvas_.ptr<float>(roi.y + y) + roi.x;
    const cv::Vec2b* print_and_coverage = averaged.ptr<cv::Vec2b>(y);
    for (int x = 0; x < roi.width; ++x) {
      const float white = print_and_coverage[x][0];
      const float coverage = print_and_coverage[x][1];
      row[x] = row[x] * (1.0f - coverage * (1.0f / 255.0f)) + black * coverage + contrast * white;
    }
  }
}

void CameraRenderer::draw_face(const Placed& placed, const Face& face, const Eigen::Isometry3d& pose_world_camera) {
  std::vector<Eigen::Vector3d> corners(4);
  for (int c = 0; c < 4; ++c) {
    corners[c] = placed.pose_camera_object * face.corners_object[c];
  }
  const Eigen::Vector3d normal_camera = placed.pose_camera_object.linear() * face.normal_object;
  if (normal_camera.dot(corners[0]) >= 0.0) {
    return;  // back face (or seen edge-on)
  }
  const Eigen::Vector3d normal_world = pose_world_camera.linear() * normal_camera;
  const double light =
      settings_.ambient + (1.0 - settings_.ambient) * std::max(0.0, -normal_world.dot(settings_.light_direction_world));
  const ObjectData& data = data_[placed.index];
  draw_polygon(corners, 255.0 * data.albedo * light);
  for (const std::size_t m : face.markers) {
    draw_marker(objects_[placed.index], m, placed.pose_camera_object, light);
  }
}

RenderStatus CameraRenderer::render(const Eigen::Isometry3d& pose_world_camera, const std::vector<ObjectPose>& poses,
                                    cv::Mat& image_mono8) {
  canvas_.create(camera_.height_px, camera_.width_px, CV_32FC1);
  canvas_.setTo(255.0 * settings_.background);
  RenderStatus status = RenderStatus::kOk;
  bool finite = pose_world_camera.matrix().allFinite();
  for (const ObjectPose& pose : poses) {
    finite = finite && pose.pose_world_object.matrix().allFinite();
  }
  if (!finite) {
    status = RenderStatus::kInvalidPose;
  } else {
    const Eigen::Isometry3d pose_camera_world = pose_world_camera.inverse();
    std::vector<Placed> placed;
    for (const ObjectPose& pose : poses) {
      const auto it =
          std::find_if(objects_.begin(), objects_.end(), [&](const BoxObject& o) { return o.id == pose.object_id; });
      if (it == objects_.end()) {
        status = RenderStatus::kUnknownObject;
        continue;
      }
      placed.push_back({static_cast<std::size_t>(it - objects_.begin()), pose_camera_world * pose.pose_world_object});
    }
    for (const std::size_t i : painter_order(placed)) {
      for (const Face& face : data_[placed[i].index].faces) {
        draw_face(placed[i], face, pose_world_camera);
      }
    }
  }
  if (settings_.blur_sigma_px > 0.0) {
    cv::GaussianBlur(canvas_, canvas_, cv::Size(0, 0), settings_.blur_sigma_px);
  }
  if (noise_stddev_ > 0.0) {
    noise_.add(canvas_);
  }
  canvas_.convertTo(image_mono8, CV_8UC1);
  return status;
}

bool CameraRenderer::occluded(const std::vector<Placed>& placed, std::size_t self,
                              const Eigen::Vector3d& point_camera) const {
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (i != self &&
        segment_hits_box(box_in_camera(objects_[placed[i].index], placed[i].pose_camera_object), point_camera)) {
      return true;
    }
  }
  return false;
}

std::vector<MarkerView> CameraRenderer::marker_views(const Eigen::Isometry3d& pose_world_camera,
                                                     const std::vector<ObjectPose>& poses) const {
  std::vector<MarkerView> views;
  const Eigen::Isometry3d pose_camera_world = pose_world_camera.inverse();
  std::vector<Placed> placed;
  for (const ObjectPose& pose : poses) {
    const auto it =
        std::find_if(objects_.begin(), objects_.end(), [&](const BoxObject& o) { return o.id == pose.object_id; });
    if (it != objects_.end()) {
      placed.push_back({static_cast<std::size_t>(it - objects_.begin()), pose_camera_world * pose.pose_world_object});
    }
  }
  constexpr int kGrid = 5;
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const BoxObject& object = objects_[placed[i].index];
    for (std::size_t m = 0; m < object.markers.size(); ++m) {
      const MarkerSpec& marker = object.markers[m];
      const Eigen::Isometry3d pose_camera_marker = placed[i].pose_camera_object * marker.pose_object_marker;
      MarkerView view;
      view.object_id = object.id;
      view.marker_id = marker.id;
      const double half = 0.5 * marker.size_m;
      const std::pair<double, double> signs[4] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
      bool in_front = true;
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector3d p =
            pose_camera_marker * Eigen::Vector3d(signs[c].first * half, signs[c].second * half, 0.0);
        in_front = in_front && p.z() > kNearPlane_m;
        view.corners_px[c] = p.z() > 0.0 ? project(p) : Eigen::Vector2d::Constant(std::nan(""));
      }
      const Eigen::Vector3d centre = pose_camera_marker.translation();
      const Eigen::Vector3d normal = pose_camera_marker.linear().col(2);
      view.distance_m = centre.norm();
      view.viewing_angle_rad = std::acos(std::clamp(-normal.dot(centre) / view.distance_m, -1.0, 1.0));
      view.front_facing = normal.dot(centre) < 0.0;
      if (view.front_facing && in_front) {
        const int modules = marker_textures_[placed[i].index][m].front().cols;
        const double reach = half * modules / (modules - 2);
        int visible = 0;
        for (int gy = 0; gy < kGrid; ++gy) {
          for (int gx = 0; gx < kGrid; ++gx) {
            const Eigen::Vector3d p = pose_camera_marker * Eigen::Vector3d(reach * (2.0 * gx / (kGrid - 1) - 1.0),
                                                                           reach * (2.0 * gy / (kGrid - 1) - 1.0), 0.0);
            if (p.z() <= kNearPlane_m) {
              continue;
            }
            const Eigen::Vector2d px = project(p);
            if (px.x() < -0.5 || px.y() < -0.5 || px.x() > camera_.width_px - 0.5 || px.y() > camera_.height_px - 0.5 ||
                occluded(placed, i, p)) {
              continue;
            }
            ++visible;
          }
        }
        view.visible_fraction = static_cast<double>(visible) / (kGrid * kGrid);
      }
      views.push_back(view);
    }
  }
  return views;
}

}  // namespace rigger::sim
