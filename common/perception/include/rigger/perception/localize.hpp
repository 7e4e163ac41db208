#pragma once
/// @file
/// Markerless localization: where a rigid part is, from a depth image and the part's triangle mesh
/// (the CAD service's tessellation of its STEP model). The global search matches, on each connected
/// surface of the image, its dominant face directions (clusters of its normals) with the model's: the two
/// largest at the model's angle to each other give an orientation, and the planes of the matched faces its
/// position up to a slide along their common edge (without a dominant face: 2560 orientations spread over
/// all of them, placed at the surface's centroid). Each is scored by how the image sees its camera-facing
/// points, and the best refined by point-to-plane ICP; with a prior pose, ICP from the prior first and the
/// global search only when that does not fit. A pose is reported only when it fits from both sides (the
/// image's points near it lie on it, and the image does not see through it) and, for a pose of the search,
/// when its squarely facing surface does not land where the image has no depth and it does not reach
/// through the support; otherwise a status says why. Pure C++, no DDS, no logging.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rigger::perception {

/// A triangle mesh in the object's frame, metres.
struct Mesh {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<Eigen::Vector3i> triangles;
};

/// Pinhole intrinsics of the depth image (no distortion), pixels.
struct DepthIntrinsics {
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
};

/// One depth frame: CV_32FC1, metres along the optical axis, NaN (or 0) where nothing was seen.
struct DepthFrame {
  cv::Mat depth_m;
  DepthIntrinsics intrinsics;
  /// The camera's optical frame (z forward, x right, y down) in the world.
  Eigen::Isometry3d pose_world_camera = Eigen::Isometry3d::Identity();
};

/// Bounds and acceptance thresholds.
struct LocalizeOptions {
  /// Points of the scene judged per pose (the rest is subsampled away) and of the model refined.
  int max_scene_points = 3000;
  int max_model_points = 1500;
  /// Scene points at or below this world height are dropped (the support under the part); unset: none.
  std::optional<double> min_height_world_m;
  /// A scene point is an inlier within this distance of the fitted model surface (about twice the
  /// depth noise's standard deviation at the working distance).
  double inlier_distance_m = 0.005;
  /// A fit is accepted with an RMS residual (over inliers) at most this, an inlier ratio (of the
  /// points of the connected surface it was fitted to) at least this, and a model support (of the part's points
  /// facing the camera, the share the image sees rather than sees through) at least this; otherwise
  /// kLowFit.
  double max_rms_m = 0.003;
  double min_inlier_ratio = 0.9;
  double min_model_support = 0.98;
  /// And the same inlier ratio, over the scene points whose normals point one way in the object's
  /// frame (6 ways: the dominant axis and its sign; ways with under 2 % of the points not judged),
  /// at least this in every way: a pose sliding along an edge leaves one face unexplained.
  double min_direction_ratio = 0.5;
  /// At least this many scene points must lie on the fitted part (else the part is not seen); also
  /// the smallest connected surface of the image searched.
  int min_supporting_points = 150;
  /// With a prior whose refinement does not fit: search the whole image (true), or report that fit's
  /// refusal (false: tracking from the last pose, where a pose far from it is no track and a search
  /// would cost several frames' time). Either way a fit from a prior is refined on the image's points
  /// within the part's box (grown by 4 cm) at the prior and judged on those within it (grown by 1 cm) at
  /// the pose found, not on a connected surface: a part set down on another, or hanging from a rope, is
  /// judged alone.
  bool search_when_prior_fails = true;
};

enum class LocalizeStatus {
  kFound,
  kNotFound,          ///< no hypothesis fits, or every surface seen is wider than the part
  kAmbiguous,         ///< two poses that are not symmetric equivalents fit equally well
  kLowFit,            ///< the best pose fits worse than the thresholds
  kBadDepth,          ///< empty image, wrong type, or no finite depth at all
  kNoVisibleSurface,  ///< finite depth, but nothing left where the part could be (e.g. all support)
  kBadMesh,           ///< the mesh has no triangles or indices out of range
};

const char* to_string(LocalizeStatus status);

/// The outcome. pose_world_object, rms_m and inlier_ratio are set for kFound (and describe the best
/// rejected pose for kLowFit and kAmbiguous); message says what went wrong otherwise.
struct LocalizeResult {
  LocalizeStatus status = LocalizeStatus::kNotFound;
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
  double rms_m = 0.0;
  double inlier_ratio = 0.0;
  int supporting_points = 0;
  double model_support = 0.0;
  /// The part's symmetries (e.g. "2-fold about x, y, z"), empty for none; among the equivalent
  /// poses the one nearest the prior is reported, or without a prior the one nearest the world axes.
  std::string symmetry;
  std::string message;
  std::chrono::microseconds elapsed{0};
};

/// Localizes one part. Construction samples the mesh once (milliseconds, no training);
/// localize() may then be called for many frames. Not thread safe: one per thread.
class Localizer {
 public:
  /// Throws std::invalid_argument for a mesh without triangles or with indices out of range.
  explicit Localizer(const Mesh& mesh, LocalizeOptions options = {});
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  /// Nothing throws: every failure is a status.
  LocalizeResult localize(const DepthFrame& frame, const std::optional<Eigen::Isometry3d>& prior_world_object = {});

  /// The symmetries found in the mesh (rotations about the object's own frame, identity first).
  const std::vector<Eigen::Matrix3d>& symmetries() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigger::perception
