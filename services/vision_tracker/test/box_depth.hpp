#pragma once
// Depth images ray-cast here (no simulator, no noise): boxes over a floor, seen by the demo camera's
// intrinsics, with a structured-light sensor's holes at depth steps. For the markerless path's tests.
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "rigger/perception/localize.hpp"

namespace rigger::vision {

struct DepthBox {
  Eigen::Isometry3d pose_world_box = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_m = Eigen::Vector3d::Zero();  ///< half sizes along the box's axes
};

/// The camera (1280 x 720, f 1000 px) at `eye`, looking at `at` (x right, y down, z forward; x level).
inline Eigen::Isometry3d camera_looking(const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d z = (at - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  pose.linear().col(0) = x;
  pose.linear().col(1) = z.cross(x);
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

/// Depth of `boxes` and, behind them, the floor (z = 0; a part seen against nothing could slide off its
/// silhouette unnoticed); holes on both sides of a depth step over 1 cm (as cell_sim's depth_noise
/// edge_gap_m).
inline perception::DepthFrame render_boxes(const Eigen::Isometry3d& pose_world_camera,
                                           const std::vector<DepthBox>& boxes) {
  perception::DepthFrame frame;
  frame.intrinsics = {1000.0, 1000.0, 640.0, 360.0};
  frame.pose_world_camera = pose_world_camera;
  frame.depth_m.create(720, 1280, CV_32FC1);
  const Eigen::Vector3d eye = pose_world_camera.translation();
  for (int v = 0; v < 720; ++v) {
    for (int u = 0; u < 1280; ++u) {
      const Eigen::Vector3d ray_camera((u - 640.0) / 1000.0, (v - 360.0) / 1000.0, 1.0);
      double t = std::numeric_limits<double>::quiet_NaN();
      for (const DepthBox& box : boxes) {
        const Eigen::Isometry3d box_from_camera = box.pose_world_box.inverse() * pose_world_camera;
        const Eigen::Vector3d o = box_from_camera.translation();
        const Eigen::Vector3d d = box_from_camera.linear() * ray_camera;
        double t_near = -std::numeric_limits<double>::infinity();
        double t_far = std::numeric_limits<double>::infinity();
        for (int i = 0; i < 3; ++i) {
          const double a = (-box.half_m[i] - o[i]) / d[i];
          const double b = (box.half_m[i] - o[i]) / d[i];
          t_near = std::max(t_near, std::min(a, b));
          t_far = std::min(t_far, std::max(a, b));
        }
        if (t_near <= t_far && t_near > 0 && !(t <= t_near)) t = t_near;
      }
      if (std::isnan(t)) {
        const Eigen::Vector3d d_world = pose_world_camera.linear() * ray_camera;
        if (d_world.z() < 0) t = -eye.z() / d_world.z();
      }
      frame.depth_m.at<float>(v, u) = static_cast<float>(t);
    }
  }
  const cv::Mat seen = frame.depth_m.clone();
  for (int v = 1; v + 1 < 720; ++v) {
    for (int u = 1; u + 1 < 1280; ++u) {
      const float here = seen.at<float>(v, u);
      for (const auto& [dv, du] : {std::pair{0, 1}, std::pair{0, -1}, std::pair{1, 0}, std::pair{-1, 0}}) {
        if (!(std::abs(seen.at<float>(v + dv, u + du) - here) <= 0.01F)) frame.depth_m.at<float>(v, u) = NAN;
      }
    }
  }
  return frame;
}

/// The camera at `eye_offset` from a box of half sizes `half` at `pose_world_box`, looking at its centre.
inline perception::DepthFrame render_box(const Eigen::Isometry3d& pose_world_box, const Eigen::Vector3d& half,
                                         const Eigen::Vector3d& eye_offset) {
  return render_boxes(camera_looking(pose_world_box.translation() + eye_offset, pose_world_box.translation()),
                      {{pose_world_box, half}});
}

}  // namespace rigger::vision
