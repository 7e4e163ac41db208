#include "tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace rigger::vision {
namespace {

// Regions are searched for markers no smaller than this share of the smallest marker side seen
// in them last time (room for approach and perspective change between frames).
constexpr double kRoiMarkerSideShare = 0.7;

TrackerConfig validated(TrackerConfig config) {
  validate(config);
  return config;
}

Eigen::Matrix<double, 6, 6> rotate_covariance(const Eigen::Matrix<double, 6, 6>& covariance, const Eigen::Matrix3d& r) {
  Eigen::Matrix<double, 6, 6> b = Eigen::Matrix<double, 6, 6>::Zero();
  b.topLeftCorner<3, 3>() = r;
  b.bottomRightCorner<3, 3>() = r;
  return b * covariance * b.transpose();
}

/// Merges overlapping rectangles until none overlap.
std::vector<cv::Rect> merge_overlapping(std::vector<cv::Rect> rects) {
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t i = 0; i < rects.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < rects.size() && !merged; ++j) {
        if ((rects[i] & rects[j]).area() > 0) {
          rects[i] |= rects[j];
          rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
      }
    }
  }
  return rects;
}

}  // namespace

Tracker::Tracker(TrackerConfig config)
    : config_(validated(std::move(config))),
      detector_(config_.detector, config_.camera),
      estimator_(config_.camera, config_.estimator) {
  reset();
}

void Tracker::reset() {
  states_.clear();
  for (const ObjectLayout& layout : config_.objects) {
    State state{PoseFilter(config_.filter), ObjectTrack{}, false};
    state.track.object_id = layout.object_id;
    states_.push_back(std::move(state));
  }
  have_stamp_ = false;
  frames_ = 0;
}

bool Tracker::set_pose_world_camera(const Eigen::Isometry3d& pose_world_camera) {
  const Eigen::Matrix3d& r = pose_world_camera.linear();
  if (!pose_world_camera.matrix().allFinite() || (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      std::abs(r.determinant() - 1.0) > 1e-6) {
    return false;
  }
  config_.pose_world_camera = pose_world_camera;
  return true;
}

std::vector<cv::Rect> Tracker::regions_of_interest(double& min_side_px) const {
  std::vector<cv::Rect> regions;
  min_side_px = std::numeric_limits<double>::max();
  const cv::Rect image(0, 0, config_.camera.width_px, config_.camera.height_px);
  for (std::size_t i = 0; i < states_.size(); ++i) {
    const State& state = states_[i];
    if (!state.seen_last_frame) {
      continue;
    }
    // Where the whole layout projects from the last pose, so markers missed last time are
    // searched too.
    double min_x = std::numeric_limits<double>::max();
    double min_y = min_x;
    double max_x = std::numeric_limits<double>::lowest();
    double max_y = max_x;
    bool any_facing = false;
    for (const MarkerPlacement& marker : config_.objects[i].markers) {
      const Eigen::Isometry3d pose_camera_marker = state.track.pose_camera_object * marker.pose_object_marker;
      if (pose_camera_marker.linear().col(2).dot(pose_camera_marker.translation()) >= 0.0) {
        continue;  // faces away: cannot be seen, and its edge-on size would say nothing
      }
      any_facing = true;
      const auto corners = marker_corners_object(marker);
      double perimeter = 0.0;
      Eigen::Vector2d previous;
      for (int c = 0; c <= 4; ++c) {
        const Eigen::Vector3d p = state.track.pose_camera_object * corners[c % 4];
        if (p.z() <= 0.0) {
          return {};  // the layout straddles the camera plane: search the full frame
        }
        const Eigen::Vector2d px = config_.camera.project(p);
        if (c > 0) {
          perimeter += (px - previous).norm();
        }
        previous = px;
        min_x = std::min(min_x, px.x());
        min_y = std::min(min_y, px.y());
        max_x = std::max(max_x, px.x());
        max_y = std::max(max_y, px.y());
      }
      min_side_px = std::min(min_side_px, 0.25 * perimeter);
    }
    if (!any_facing) {
      return {};  // nothing of it should be visible where it was: search the full frame
    }
    const double margin =
        config_.detector.roi_margin_fraction * std::max(max_x - min_x, max_y - min_y) + config_.detector.roi_margin_px;
    const cv::Rect region(
        cv::Point(static_cast<int>(std::floor(min_x - margin)), static_cast<int>(std::floor(min_y - margin))),
        cv::Point(static_cast<int>(std::ceil(max_x + margin)), static_cast<int>(std::ceil(max_y + margin))));
    const cv::Rect clipped = region & image;
    if (!clipped.empty()) {
      regions.push_back(clipped);
    }
  }
  min_side_px = std::max(8.0, kRoiMarkerSideShare * min_side_px);
  return merge_overlapping(regions);
}

bool Tracker::any_missing(const std::vector<DetectedMarker>& markers, bool only_tracked) const {
  for (std::size_t i = 0; i < states_.size(); ++i) {
    if (only_tracked && !states_[i].seen_last_frame) {
      continue;
    }
    const ObjectLayout& layout = config_.objects[i];
    const bool found = std::any_of(markers.begin(), markers.end(), [&](const DetectedMarker& d) {
      return std::any_of(layout.markers.begin(), layout.markers.end(),
                         [&](const MarkerPlacement& m) { return m.id == d.id; });
    });
    if (!found) {
      return true;
    }
  }
  return false;
}

FrameResult Tracker::process(const cv::Mat& image, Stamp stamp) {
  FrameResult result;
  result.stamp = stamp;
  if (image.empty()) {
    result.status = FrameStatus::kEmptyImage;
    return result;
  }
  if (image.type() != CV_8UC1) {
    result.status = FrameStatus::kWrongEncoding;
    return result;
  }
  if (image.cols != config_.camera.width_px || image.rows != config_.camera.height_px) {
    result.status = FrameStatus::kWrongSize;
    return result;
  }
  if (have_stamp_ && stamp <= last_stamp_) {
    result.status = FrameStatus::kOutOfOrder;
    return result;
  }
  have_stamp_ = true;
  last_stamp_ = stamp;
  ++frames_;

  // Search around the tracked objects first; the full frame when there is nothing to track, when
  // a tracked object was not found where expected (moved fast, occluded), or periodically while an
  // object is missing (re-acquisition).
  std::vector<DetectedMarker> markers;
  bool full_frame = true;
  if (config_.detector.track_in_roi) {
    double min_side_px = 0.0;
    const std::vector<cv::Rect> regions = regions_of_interest(min_side_px);
    if (!regions.empty()) {
      markers = detector_.detect(image, regions, min_side_px);
      const bool reacquire = frames_ % config_.detector.reacquire_every_n_frames == 0 && any_missing(markers, false);
      full_frame = any_missing(markers, true) || reacquire;
    }
  }
  if (full_frame) {
    markers = detector_.detect(image, {}, config_.detector.min_marker_side_px);
  }
  result.searched_full_frame = full_frame;
  result.markers_detected = static_cast<int>(markers.size());

  const Eigen::Isometry3d pose_camera_world = config_.pose_world_camera.inverse();
  for (std::size_t i = 0; i < states_.size(); ++i) {
    State& state = states_[i];
    ObjectTrack& track = state.track;
    std::optional<Eigen::Isometry3d> prior;
    if (track.has_pose) {
      prior = track.pose_camera_object;
    }
    PoseEstimate estimate;
    track.estimate_status = estimator_.estimate(config_.objects[i], markers, prior, estimate);
    track.detected = track.estimate_status == EstimateStatus::kOk;
    state.seen_last_frame = track.detected;
    if (track.detected) {
      const Eigen::Isometry3d measured_world = config_.pose_world_camera * estimate.pose_camera_object;
      state.filter.update(measured_world, stamp);
      track.has_pose = true;
      track.stamp = stamp;
      track.pose_world_object = state.filter.pose();
      track.pose_camera_object = pose_camera_world * track.pose_world_object;
      track.quality = estimate.quality;
      track.covariance_world = rotate_covariance(estimate.covariance_camera, config_.pose_world_camera.linear());
      track.markers_used = estimate.markers_used;
      track.reprojection_rms_px = estimate.reprojection_rms_px;
    } else {
      // Lost in this image: say so at once; keep the last pose with its own (older) stamp.
      track.quality = 0.0;
      track.markers_used = 0;
    }
    track.localized = track.has_pose && stamp - track.stamp <= config_.lost_after;
    result.objects.push_back(track);
  }
  return result;
}

std::vector<ObjectTrack> Tracker::tracks_at(Stamp now) const {
  std::vector<ObjectTrack> tracks;
  for (const State& state : states_) {
    ObjectTrack track = state.track;
    track.detected = false;
    track.quality = 0.0;
    track.localized = track.has_pose && now - track.stamp <= config_.lost_after;
    tracks.push_back(track);
  }
  return tracks;
}

}  // namespace rigger::vision
