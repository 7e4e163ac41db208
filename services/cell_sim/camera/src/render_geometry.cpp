#include "render_geometry.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rigger::sim::render_geometry {

Box box_in_camera(const BoxObject& object, const Eigen::Isometry3d& pose_camera_object) {
  const Eigen::Isometry3d pose_camera_box = pose_camera_object * object.pose_object_box;
  return {pose_camera_box.translation(), pose_camera_box.linear(), 0.5 * object.size_m};
}

int front_of(const Box& a, const Box& b) {
  std::vector<Eigen::Vector3d> axes;
  axes.reserve(15);
  for (int i = 0; i < 3; ++i) {
    axes.push_back(a.axes.col(i));
    axes.push_back(b.axes.col(i));
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d cross = a.axes.col(i).cross(b.axes.col(j));
      if (cross.norm() > 1e-9) {
        axes.push_back(cross.normalized());
      }
    }
  }
  for (const Eigen::Vector3d& axis : axes) {
    const double ca = a.centre.dot(axis);
    const double cb = b.centre.dot(axis);
    double ra = 0.0;
    double rb = 0.0;
    for (int i = 0; i < 3; ++i) {
      ra += a.half[i] * std::abs(a.axes.col(i).dot(axis));
      rb += b.half[i] * std::abs(b.axes.col(i).dot(axis));
    }
    if (ca + ra <= cb - rb) {
      // a below b along the axis; the camera (projection 0) on a's side of the gap's middle
      // means every ray meets a first.
      const double mid = 0.5 * (ca + ra + cb - rb);
      return 0.0 < mid ? 1 : -1;
    }
    if (cb + rb <= ca - ra) {
      const double mid = 0.5 * (cb + rb + ca - ra);
      return 0.0 > mid ? 1 : -1;
    }
  }
  return 0;
}

bool segment_hits_box(const Box& box, const Eigen::Vector3d& point) {
  const Eigen::Vector3d origin = box.axes.transpose() * (-box.centre);
  const Eigen::Vector3d dir = box.axes.transpose() * (point - box.centre) - origin;
  double t_min = 0.0;
  double t_max = 1.0 - 1e-9;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(dir[k]) < 1e-15) {
      if (std::abs(origin[k]) > box.half[k]) {
        return false;
      }
      continue;
    }
    double t1 = (-box.half[k] - origin[k]) / dir[k];
    double t2 = (box.half[k] - origin[k]) / dir[k];
    if (t1 > t2) {
      std::swap(t1, t2);
    }
    t_min = std::max(t_min, t1);
    t_max = std::min(t_max, t2);
    if (t_min > t_max) {
      return false;
    }
  }
  return true;
}

std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& polygon) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(polygon.size() + 2);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a.z() >= kNearPlane_m;
    const bool b_in = b.z() >= kNearPlane_m;
    if (a_in) {
      out.push_back(a);
    }
    if (a_in != b_in) {
      const double t = (kNearPlane_m - a.z()) / (b.z() - a.z());
      out.push_back(a + t * (b - a));
    }
  }
  return out;
}

std::vector<Eigen::Vector2d> clip_half_plane(const std::vector<Eigen::Vector2d>& polygon, int axis, double bound,
                                             double sign) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(polygon.size() + 2);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = sign * a[axis] >= sign * bound;
    const bool b_in = sign * b[axis] >= sign * bound;
    if (a_in) {
      out.push_back(a);
    }
    if (a_in != b_in) {
      const double t = (bound - a[axis]) / (b[axis] - a[axis]);
      out.push_back(a + t * (b - a));
    }
  }
  return out;
}

cv::Rect pixel_bounds(const std::vector<Eigen::Vector2d>& points, int width, int height) {
  double min_x = std::numeric_limits<double>::max();
  double min_y = min_x;
  double max_x = std::numeric_limits<double>::lowest();
  double max_y = max_x;
  for (const Eigen::Vector2d& p : points) {
    min_x = std::min(min_x, p.x());
    min_y = std::min(min_y, p.y());
    max_x = std::max(max_x, p.x());
    max_y = std::max(max_y, p.y());
  }
  // Pixel i covers [i - 0.5, i + 0.5).
  const int x0 = std::max(0, static_cast<int>(std::floor(min_x + 0.5)));
  const int y0 = std::max(0, static_cast<int>(std::floor(min_y + 0.5)));
  const int x1 = std::min(width, static_cast<int>(std::floor(max_x + 0.5)) + 1);
  const int y1 = std::min(height, static_cast<int>(std::floor(max_y + 0.5)) + 1);
  if (x1 <= x0 || y1 <= y0) {
    return {};
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

int supersampling_for(const cv::Rect& roi, int wanted, double budget) {
  int s = wanted;
  while (s > 1 && static_cast<double>(roi.area()) * s * s > budget) {
    --s;
  }
  return s;
}

Eigen::Matrix3d image_to_supersampled(const cv::Rect& roi, int s) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(0, 0) = s;
  m(1, 1) = s;
  m(0, 2) = s * (0.5 - roi.x) - 0.5;
  m(1, 2) = s * (0.5 - roi.y) - 0.5;
  return m;
}

void blend_uniform(cv::Mat& canvas, const cv::Rect& roi, const cv::Mat& coverage, double value) {
  const float v = static_cast<float>(value);
  for (int y = 0; y < roi.height; ++y) {
    float* row = canvas.ptr<float>(roi.y + y) + roi.x;
    const std::uint8_t* cov = coverage.ptr<std::uint8_t>(y);
    for (int x = 0; x < roi.width; ++x) {
      const float a = cov[x] * (1.0f / 255.0f);
      row[x] += a * (v - row[x]);
    }
  }
}

std::vector<cv::Mat> marker_texture_levels(const cv::aruco::Dictionary& dictionary, int id,
                                           const std::vector<int>& texels_per_module) {
  const int modules = dictionary.markerSize + 2;  // bits plus the one-module black border
  cv::Mat printed;
  dictionary.drawMarker(id, modules, printed, 1);
  cv::Mat with_quiet_zone;
  cv::copyMakeBorder(printed, with_quiet_zone, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(255));
  std::vector<cv::Mat> levels;
  for (const int texels : texels_per_module) {
    cv::Mat magnified;
    cv::resize(with_quiet_zone, magnified, cv::Size(), texels, texels, cv::INTER_NEAREST);
    cv::Mat texture;
    cv::merge(std::vector<cv::Mat>{magnified, cv::Mat(magnified.size(), CV_8UC1, cv::Scalar(255))}, texture);
    levels.push_back(texture);
  }
  return levels;
}

Eigen::Matrix3d texture_to_camera(const Eigen::Isometry3d& pose_camera_marker, double half_m, double texel_m) {
  // Texel (u, v) has its centre at the marker-plane point (-half + (u + 0.5) t, half - (v + 0.5) t).
  Eigen::Matrix3d texture_to_plane;
  texture_to_plane << texel_m, 0, -half_m + 0.5 * texel_m,  //
      0, -texel_m, half_m - 0.5 * texel_m,                  //
      0, 0, 1;
  Eigen::Matrix3d plane_to_camera;
  plane_to_camera.col(0) = pose_camera_marker.linear().col(0);
  plane_to_camera.col(1) = pose_camera_marker.linear().col(1);
  plane_to_camera.col(2) = pose_camera_marker.translation();
  return plane_to_camera * texture_to_plane;
}

cv::Matx33d to_cv(const Eigen::Matrix3d& m) {
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out(r, c) = m(r, c);
    }
  }
  return out;
}

}  // namespace rigger::sim::render_geometry
