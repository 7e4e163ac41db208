#pragma once
/// @file
/// Configuration of the vision tracker: the camera, the marker layouts of the tracked objects
/// (both from the cell file, read with rigger_cell_config) and the tuning of detection, pose
/// estimation, filtering and the lost-tracking rule.

#include <Eigen/Geometry>

#include <array>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::vision {

/// Image stamps are wall-clock capture times, as on the wire (rigger::WallTime).
using Stamp = std::chrono::system_clock::time_point;

/// A setup error in the tracker configuration; what() names the field and what was expected.
class TrackerConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The camera the tracker looks through: the cell file's intrinsics and lens distortion.
using cell::CameraIntrinsics;

/// One square marker of an object's layout. Marker frame as OpenCV ArUco: origin at the centre,
/// x right and y up on the printed image, z out of it; size_m is the black border's outer edge.
struct MarkerPlacement {
  int id = 0;
  double size_m = 0.0;
  Eigen::Isometry3d pose_object_marker = Eigen::Isometry3d::Identity();
};

/// The markers that identify one object and locate it (a rigid "board").
struct ObjectLayout {
  std::string object_id;
  std::vector<MarkerPlacement> markers;
};

/// Marker detection (OpenCV aruco, 4.6 API).
struct DetectorSettings {
  /// cv::aruco::PREDEFINED_DICTIONARY_NAME.
  int dictionary = 0;  // DICT_4X4_50
  /// The fast ArUco3 path: segment a downscaled image, refine corners up the pyramid.
  bool use_aruco3 = true;
  /// Smallest marker side (pixels of the full image) to find in a full-frame search. ArUco3
  /// downscales so that such a marker is min_side_canonical_px long in the segmented image.
  double min_marker_side_px = 24.0;
  int min_side_canonical_px = 16;
  /// Refine corners by fitting straight lines to the four outer edges (subpixel, unbiased for
  /// antialiased or blurred edges) instead of keeping the corner-window estimates alone.
  bool refine_edges = true;
  /// Search only around the objects' previous positions; a miss falls back to the full frame in
  /// the same call.
  bool track_in_roi = true;
  /// Region margin around an object's predicted marker area: this fraction of its size plus px
  /// (at 30 Hz, 24 px is a marker 1.5 m away moving at 1 m/s).
  double roi_margin_fraction = 0.15;
  int roi_margin_px = 24;
  /// Adaptive-threshold window (pixels of ArUco3's segmentation image) in search regions, where
  /// the markers' size is known; 0: OpenCV's default sweep of three windows. The full frame always
  /// uses the sweep.
  int region_threshold_window_px = 11;
  /// Objects not seen in the previous frame are searched in the full frame every n frames
  /// (1: every frame). Objects that were tracked fall back at once.
  int reacquire_every_n_frames = 2;
};

/// Pose estimation and its quality figure.
struct EstimatorSettings {
  /// Reprojection RMS above which an estimate is rejected (the object counts as not detected).
  double max_reprojection_rms_px = 3.0;
  /// Quality factor exp(-(rms / scale)^2) of the reprojection error.
  double quality_reprojection_scale_px = 1.0;
  /// Viewing angle (marker normal vs line of sight): full quality up to good, zero at grazing.
  double good_viewing_angle_deg = 60.0;
  double grazing_viewing_angle_deg = 85.0;
  /// Below this quality an estimate is not used (the object counts as not detected).
  double min_quality = 0.05;
  /// Floor of the per-coordinate image noise assumed in the covariance, pixels.
  double min_pixel_sigma_px = 0.05;
};

/// Temporal filter: constant-velocity alpha-beta filter on SE(3).
struct FilterSettings {
  bool enabled = true;
  /// Share of the innovation taken into the pose (1: no smoothing) and into the velocity. The
  /// defaults follow Benedict-Bordner (beta = alpha^2 / (2 - alpha)): single images are already
  /// accurate to a fraction of a millimetre, so the filter is light and lags little when the load
  /// swings (about 1.4 mm at 0.5 m/s^2 and 30 Hz).
  double position_gain = 0.7;
  double velocity_gain = 0.38;
  /// Longest gap the filter predicts across; after a longer gap it restarts from the measurement.
  std::chrono::nanoseconds max_prediction{std::chrono::milliseconds(200)};
  /// An innovation beyond these restarts the filter at the measurement (the object was moved).
  double reset_distance_m = 0.05;
  double reset_angle_deg = 10.0;
};

/// Everything the tracker needs.
struct TrackerConfig {
  CameraIntrinsics camera;
  /// The camera's pose in the world (optical frame), for world-frame outputs.
  Eigen::Isometry3d pose_world_camera = Eigen::Isometry3d::Identity();
  std::vector<ObjectLayout> objects;
  DetectorSettings detector;
  EstimatorSettings estimator;
  FilterSettings filter;
  /// The lost-tracking rule: an object not detected for longer than this is no longer localized.
  std::chrono::nanoseconds lost_after{std::chrono::milliseconds(500)};
};

/// Whether two configurations see the same: the same camera (intrinsics, distortion, pose) and the same
/// objects with the same marker layouts. Tuning is not compared.
bool same_view(const TrackerConfig& a, const TrackerConfig& b);

/// Throws TrackerConfigError naming the first bad field (e.g. "objects[1].markers[0].size_m").
void validate(const TrackerConfig& config);

/// The camera `camera_id` (intrinsics, pose in the root frame), every object with markers of a validated
/// cell file and, after them, every device's calibration board (by cell::calibration_board_id); tuning keeps its
/// defaults. Throws cell::CellFileError naming the file and the JSON pointer (no such camera, no intrinsics, layouts in
/// different dictionaries).
TrackerConfig tracker_config_from_cell(const cell::CellFile& file, const std::string& camera_id);

}  // namespace rigger::vision
