#pragma once
/// @file
/// Finds ArUco markers in grey images (OpenCV 4.6 aruco, ArUco3 fast path) and refines their
/// corners to a few hundredths of a pixel by fitting straight lines to the markers' outer edges.

#include "tracker_config.hpp"

#include <Eigen/Core>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>

#include <array>
#include <vector>

namespace rigger::vision {

/// A marker found in an image.
struct DetectedMarker {
  int id = 0;
  /// Outer corners of the black border in OpenCV ArUco order (top-left, top-right, bottom-right,
  /// bottom-left of the printed image), in ideal pinhole pixel coordinates (lens distortion
  /// removed): project with the camera matrix alone.
  std::array<Eigen::Vector2d, 4> corners_px{};
  /// The corners come from the edge-line fit (else from corner windows only: less accurate).
  bool edge_refined = false;
};

/// Samples a marker's four outer edges and returns subpixel edge points, one list per edge (edge k
/// runs from corner k to corner k + 1), in the image's (distorted) pixel coordinates. Each point is
/// where a pixel row or column crosses the edge, measured as the area under the normalised
/// intensity profile across it: exact for antialiased and symmetrically blurred straight edges.
/// modules_across is the marker's width in modules including its black border (6 for 4x4).
/// Returns false when the marker is too small, too low in contrast or too close to the border.
bool sample_marker_edges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners_px, int modules_across,
                         std::array<std::vector<Eigen::Vector2d>, 4>& edge_points_px);

/// Coarse edge points: on each row or column crossing an edge, the steepest dark-to-light step
/// outwards within most of a module of the estimate (tolerates corner estimates pixels off).
bool locate_marker_edges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners_px, int modules_across,
                         std::array<std::vector<Eigen::Vector2d>, 4>& edge_points_px);

/// Fits a line to each edge's points (with outlier rejection) and intersects neighbours.
/// Returns false when an edge has too few consistent points.
bool corners_from_edges(const std::array<std::vector<Eigen::Vector2d>, 4>& edge_points_px,
                        std::array<Eigen::Vector2d, 4>& corners_px);

/// Detects the markers of one dictionary. Not thread safe (one detector per thread).
class MarkerDetector {
 public:
  /// Throws TrackerConfigError for an unusable dictionary.
  MarkerDetector(const DetectorSettings& settings, const CameraIntrinsics& camera);

  /// Detects markers in gray (CV_8UC1, the camera's size) within regions (full frame when empty;
  /// regions are clipped to the image). min_marker_side_px: the smallest marker side to look for.
  /// A marker id seen twice is dropped (ambiguous). Results are sorted by id.
  std::vector<DetectedMarker> detect(const cv::Mat& gray, const std::vector<cv::Rect>& regions,
                                     double min_marker_side_px);

 private:
  void detect_region(const cv::Mat& gray, const cv::Rect& region, double min_marker_side_px,
                     std::vector<std::vector<cv::Point2f>>& corners, std::vector<int>& ids);
  void refine(const cv::Mat& gray, const std::vector<cv::Point2f>& raw, DetectedMarker& marker) const;
  void undistort(std::vector<cv::Point2f>& points) const;

  DetectorSettings settings_;
  CameraIntrinsics camera_;
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
  cv::Mat camera_matrix_;
  cv::Mat distortion_;
  bool distorted_ = false;
  int modules_across_ = 6;
};

}  // namespace rigger::vision
