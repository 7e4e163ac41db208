#pragma once
// Internal: the cell file's ArUco markers, drawn into MuJoCo's pinhole render after it is made.
// Each marker (with a white quiet zone of one module) is mapped onto its face plane by an exact
// homography, drawn only where the depth buffer shows that plane (so whatever stands in front of
// it hides it), and shaded with the brightness MuJoCo rendered for the face under it.

#include <mujoco/mujoco.h>

#include <opencv2/core.hpp>

#include <Eigen/Geometry>

#include <vector>

#include "lens_map.hpp"
#include "rigger/sim/camera_renderer.hpp"
#include "rigger/sim/camera_scene.hpp"

namespace rigger::sim::detail {

/// The markers of a set of objects, ready to draw. Not thread safe.
class MarkerDecals {
 public:
  /// Throws std::invalid_argument for an unknown dictionary or a marker id outside it.
  MarkerDecals(std::vector<BoxObject> objects, int dictionary, double marker_white, double marker_black);

  /// Draws the markers of the objects in `poses` into render_rgb (CV_8UC3, rows bottom-up as
  /// `render` describes), testing each pixel against depth (CV_32FC1 window depth). A marker is
  /// drawn only where the model has a surface under it (a ray into its face hits a geom within a
  /// few millimetres); that geom's colour gives the face's albedo for shading. Returns how many
  /// markers were drawn (some of each may still be hidden).
  int draw(const mjModel& model, const mjData& data, const PinholeRender& render, const DepthScale& depth_scale,
           const Eigen::Isometry3d& pose_world_camera, const std::vector<ObjectPose>& poses, const cv::Mat& depth,
           cv::Mat& render_rgb) const;

 private:
  bool draw_one(const mjModel& model, const mjData& data, const PinholeRender& render, const DepthScale& depth_scale,
                const Eigen::Isometry3d& pose_world_camera, const Eigen::Isometry3d& pose_world_marker,
                const std::vector<cv::Mat>& levels, double size_m, const cv::Mat& depth, cv::Mat& render_rgb) const;

  std::vector<BoxObject> objects_;
  double white_ = 0.92;
  double black_ = 0.05;
  /// Per object, per marker, per magnification (1, 2, 4 ... texels per module): the printed marker
  /// with its quiet zone; channel 0 the print, channel 1 all 255 (its coverage once warped). CV_8UC2.
  std::vector<std::vector<std::vector<cv::Mat>>> textures_;
  mutable cv::Mat warped_;
};

}  // namespace rigger::sim::detail
