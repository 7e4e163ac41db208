#pragma once
// Internal: the camera renderer's geometry (boxes in the camera frame, which hides which, clipping) and
// rasterization helpers (pixel bounds, supersampling, blending). Pure functions of their arguments.

#include <opencv2/aruco/dictionary.hpp>
#include <opencv2/core.hpp>

#include <vector>

#include <Eigen/Geometry>

#include "rigger/sim/camera_scene.hpp"

namespace rigger::sim::render_geometry {

/// The camera's near clipping plane (m, along the optical axis).
constexpr double kNearPlane_m = 0.01;

/// A box in the camera frame.
struct Box {
  Eigen::Vector3d centre;
  Eigen::Matrix3d axes;  // columns: the box axes (unit)
  Eigen::Vector3d half;
};

/// `object`'s box in the camera frame, the object at `pose_camera_object`.
Box box_in_camera(const BoxObject& object, const Eigen::Isometry3d& pose_camera_object);

/// Separating-axis test between two boxes, camera at the origin. Returns +1 when a is wholly on the
/// camera's side of a separating plane (a may hide b, never the reverse), -1 for the converse, and
/// 0 when the boxes intersect or the camera lies in the gap (then neither can hide the other, or
/// the boxes overlap and no order is right everywhere).
int front_of(const Box& a, const Box& b);

/// Whether the segment from the camera origin to point (both camera frame) passes through the box
/// before reaching the point.
bool segment_hits_box(const Box& box, const Eigen::Vector3d& point);

/// The part of a camera-frame polygon at or beyond the near plane (kNearPlane_m).
std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& polygon);

/// Sutherland-Hodgman against one half plane: keeps points with sign * p[axis] >= sign * bound.
std::vector<Eigen::Vector2d> clip_half_plane(const std::vector<Eigen::Vector2d>& polygon, int axis, double bound,
                                             double sign);

/// The image rows/columns a polygon's bounding box touches, clipped to the image; empty if none.
cv::Rect pixel_bounds(const std::vector<Eigen::Vector2d>& points, int width, int height);

/// The supersampling factor for roi: `wanted`, lowered until roi's samples fit in `budget`.
int supersampling_for(const cv::Rect& roi, int wanted, double budget);

/// Maps image pixel coordinates to the coordinates of an s-times supersampled grid over roi
/// (sample j of pixel i has its centre at i - 0.5 + (j + 0.5) / s).
Eigen::Matrix3d image_to_supersampled(const cv::Rect& roi, int s);

/// The printed marker `id` with a white quiet zone of one module, magnified to each of
/// texels_per_module (nearest), as CV_8UC2: channel 0 the print, channel 1 all 255 (its coverage
/// once warped, 0 outside).
std::vector<cv::Mat> marker_texture_levels(const cv::aruco::Dictionary& dictionary, int id,
                                           const std::vector<int>& texels_per_module);

/// The homography from texture pixels (centres at integer coordinates, OpenCV's convention) of a
/// marker texture covering [-half_m, half_m]^2 of the marker plane (x right, y up) to homogeneous
/// optical-frame points: [r1 r2 t] A. Multiply by a camera matrix for image pixels.
Eigen::Matrix3d texture_to_camera(const Eigen::Isometry3d& pose_camera_marker, double half_m, double texel_m);

/// An Eigen 3x3 as OpenCV's.
cv::Matx33d to_cv(const Eigen::Matrix3d& m);

/// canvas = canvas * (1 - alpha) + value * alpha over roi, alpha from an 8-bit coverage image.
void blend_uniform(cv::Mat& canvas, const cv::Rect& roi, const cv::Mat& coverage, double value);

}  // namespace rigger::sim::render_geometry
