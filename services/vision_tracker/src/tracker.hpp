#pragma once
/// @file
/// The vision tracker's logic, without DDS: one call per camera image returns every configured
/// object's pose with its quality, and applies the lost-tracking rule.
///
/// Lost-tracking rule: an object not detected in an image has quality 0 in that image's result at
/// once; its last pose is still reported, but with the stamp of the image it came from (never the
/// current one), and localized stays true only while that stamp is at most lost_after old.

#include "marker_detector.hpp"
#include "pose_estimator.hpp"
#include "pose_filter.hpp"
#include "tracker_config.hpp"

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rigger::vision {

/// One object's state after an image.
struct ObjectTrack {
  std::string object_id;
  /// Found in this image (quality > 0).
  bool detected = false;
  /// Has a pose whose stamp is at most lost_after older than the image's.
  bool localized = false;
  /// The object was seen at least once since start or reset (else the pose is meaningless).
  bool has_pose = false;
  /// In [0, 1]; 0 whenever not detected in this image.
  double quality = 0.0;
  /// Stamp of the image the pose was measured in.
  Stamp stamp{};
  /// Filtered pose at stamp.
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_camera_object = Eigen::Isometry3d::Identity();
  /// Covariance of (x, y, z, rot x, rot y, rot z) in world axes, of the single-image estimate.
  Eigen::Matrix<double, 6, 6> covariance_world = Eigen::Matrix<double, 6, 6>::Zero();
  int markers_used = 0;
  double reprojection_rms_px = 0.0;
  /// Why the object was not detected in this image (kOk when it was).
  EstimateStatus estimate_status = EstimateStatus::kNoMarkers;
};

enum class FrameStatus {
  kOk,
  kEmptyImage,
  /// Not CV_8UC1 (mono8).
  kWrongEncoding,
  /// Not the configured camera's size.
  kWrongSize,
  /// Stamp not after the previous image's: ignored, nothing changed.
  kOutOfOrder,
};

/// The outcome of one image.
struct FrameResult {
  FrameStatus status = FrameStatus::kOk;
  Stamp stamp{};
  /// One per configured object, in configuration order; empty unless status is kOk.
  std::vector<ObjectTrack> objects;
  /// Markers of any configured or unknown id found in the image.
  int markers_detected = 0;
  /// The whole image was searched (else only regions around the tracked objects).
  bool searched_full_frame = false;
};

/// Not thread safe: one tracker per camera stream.
class Tracker {
 public:
  /// Throws TrackerConfigError naming the bad field.
  explicit Tracker(TrackerConfig config);

  /// Processes one mono8 image taken at stamp. Never throws for bad input: see FrameStatus.
  FrameResult process(const cv::Mat& image_mono8, Stamp stamp);

  /// The tracks as of now without a new image (e.g. when the camera has gone silent): the
  /// lost-tracking rule evaluated at now, quality 0 for all.
  std::vector<ObjectTrack> tracks_at(Stamp now) const;

  /// Updates the camera's world pose (e.g. from the world model); world outputs use it from the
  /// next image on. Returns false, changing nothing, unless it is a finite rigid transform.
  bool set_pose_world_camera(const Eigen::Isometry3d& pose_world_camera);

  /// Forgets all tracks.
  void reset();

  const TrackerConfig& config() const { return config_; }

 private:
  struct State {
    PoseFilter filter;
    ObjectTrack track;
    bool seen_last_frame = false;
  };

  std::vector<cv::Rect> regions_of_interest(double& min_side_px) const;
  bool any_missing(const std::vector<DetectedMarker>& markers, bool only_tracked) const;

  TrackerConfig config_;
  MarkerDetector detector_;
  PoseEstimator estimator_;
  std::vector<State> states_;
  bool have_stamp_ = false;
  Stamp last_stamp_{};
  long long frames_ = 0;
};

}  // namespace rigger::vision
