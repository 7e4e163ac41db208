#pragma once
/// @file
/// An object's 6D pose from the detected markers of its layout (all their corners together, as a
/// board), with a quality figure and a covariance.

#include "marker_detector.hpp"
#include "tracker_config.hpp"

#include <Eigen/Geometry>

#include <optional>
#include <vector>

namespace rigger::vision {

/// Pose of one object in the camera's optical frame, from one image.
struct PoseEstimate {
  Eigen::Isometry3d pose_camera_object = Eigen::Isometry3d::Identity();
  /// In [0, 1]: reprojection error x share of the layout seen x viewing angle x ambiguity.
  double quality = 0.0;
  double reprojection_rms_px = 0.0;
  int markers_used = 0;
  /// Largest angle between a used marker's normal and its line of sight, radians.
  double max_viewing_angle_rad = 0.0;
  /// The two mirror solutions of a planar layout fitted almost equally well.
  bool ambiguous = false;
  /// Covariance of (x, y, z, rot x, rot y, rot z) in the camera frame (m^2, rad^2; rotation as a
  /// small rotation applied on the left), from the reprojection Jacobian.
  Eigen::Matrix<double, 6, 6> covariance_camera = Eigen::Matrix<double, 6, 6>::Zero();
};

enum class EstimateStatus {
  kOk,
  /// None of the layout's markers were detected.
  kNoMarkers,
  /// PnP failed or gave a pose behind the camera.
  kFailed,
  /// The best pose reprojects worse than the configured limit (a false or misidentified marker).
  kReprojectionTooLarge,
  /// Below the configured minimum quality.
  kLowQuality,
};

/// Stateless apart from its configuration; const methods are thread safe.
class PoseEstimator {
 public:
  PoseEstimator(const CameraIntrinsics& camera, const EstimatorSettings& settings);

  /// Estimates layout's pose from those of markers that belong to it. prior (camera frame), when
  /// given, picks between the two mirror solutions of a planar layout when they fit alike.
  EstimateStatus estimate(const ObjectLayout& layout, const std::vector<DetectedMarker>& markers,
                          const std::optional<Eigen::Isometry3d>& prior_camera_object, PoseEstimate& out) const;

 private:
  Eigen::Vector2d project(const Eigen::Isometry3d& pose_camera_object, const Eigen::Vector3d& point_object) const;
  /// J^T J and J^T r of the reprojection residuals at pose (perturbation: position, then a small
  /// rotation on the left).
  void normal_equations(const std::vector<Eigen::Vector3d>& object_points,
                        const std::vector<Eigen::Vector2d>& image_points, const Eigen::Isometry3d& pose,
                        Eigen::Matrix<double, 6, 6>& jtj, Eigen::Matrix<double, 6, 1>& jtr) const;
  /// Gauss-Newton refinement of pose; false when it diverges or leaves points behind the camera.
  bool refine(const std::vector<Eigen::Vector3d>& object_points, const std::vector<Eigen::Vector2d>& image_points,
              Eigen::Isometry3d& pose) const;

  CameraIntrinsics camera_;
  EstimatorSettings settings_;
};

/// The four corners of a marker in its object's frame, in ArUco order.
std::array<Eigen::Vector3d, 4> marker_corners_object(const MarkerPlacement& marker);

/// Rotation angle of a^-1 b, radians.
double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace rigger::vision
