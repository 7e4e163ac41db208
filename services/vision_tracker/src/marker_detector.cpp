#include "marker_detector.hpp"

#include <Eigen/Eigenvalues>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace rigger::vision {
namespace {

constexpr int kMinEdgeSamples = 4;
constexpr double kMinContrast = 20.0;  // grey levels between quiet zone and black border
// Lines averaged for the local quiet-zone and black levels (gradual shading along an edge).
constexpr int kLevelWindow = 3;
constexpr double kMaxReach_px = 3.5;

/// Total-least-squares line through points, as a*x + b*y + c = 0 with (a, b) unit (well
/// conditioned for any edge direction).
Eigen::Vector3d fit_line(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) {
    mean += p;
  }
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : points) {
    scatter += (p - mean) * (p - mean).transpose();
  }
  // Total least squares: the normal is the direction of least spread.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  const Eigen::Vector2d normal = eig.eigenvectors().col(0);
  return {normal.x(), normal.y(), -normal.dot(mean)};
}

/// The pixel rows (or columns) crossing one marker edge, and the window across it.
struct EdgeScan {
  // Pixel axis scanned across the edge: 0 = along rows (x), 1 = along columns (y).
  int scan = 0;
  // Window: the crossing pixel +- half.
  int half = 0;
  // The quiet zone is at the window's high end.
  bool white_high = true;
  // Module width across the edge.
  double module_px = 0.0;
  // (row or column, predicted crossing) of each scan line.
  std::vector<std::pair<int, double>> lines;
};

/// Plans the scan of edge k (corner k -> k + 1) of a marker. reach_px: how far the window reaches
/// on either side of the edge, capped at max_reach_modules of a module.
bool plan_edge_scan(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, int k, int modules_across,
                    double max_reach_modules, double max_reach_px, EdgeScan& plan) {
  const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  const Eigen::Vector2d a = corners[k];
  const Eigen::Vector2d b = corners[(k + 1) % 4];
  const double length = (b - a).norm();
  if (!(length > 4.0)) {
    return false;
  }
  const Eigen::Vector2d dir = (b - a) / length;
  Eigen::Vector2d normal(dir.y(), -dir.x());
  if (normal.dot(a - centre) < 0.0) {
    normal = -normal;  // outwards, towards the quiet zone
  }
  // The window across the edge must stay within one module on each side: the black border
  // inside, the quiet zone outside.
  const Eigen::Vector2d opposite_mid = 0.5 * (corners[(k + 2) % 4] + corners[(k + 3) % 4]);
  plan.module_px = std::abs((opposite_mid - a).dot(normal)) / modules_across;
  const double reach_px = std::min(max_reach_modules * plan.module_px, max_reach_px);
  if (reach_px < 1.5) {
    return false;
  }
  // Scan along the pixel axis closest to the normal: rows for steep edges, columns otherwise.
  plan.scan = std::abs(normal.x()) >= std::abs(normal.y()) ? 0 : 1;
  const int along = 1 - plan.scan;
  plan.half = std::max(2, static_cast<int>(std::floor(reach_px / std::abs(normal[plan.scan]))));
  plan.white_high = normal[plan.scan] > 0.0;
  // Keep clear of the corners, where the window would cross the neighbouring edges.
  const double margin_px = 1.5 * plan.half + 2.0;
  const int limit = plan.scan == 0 ? gray.cols : gray.rows;
  const int c_limit = plan.scan == 0 ? gray.rows : gray.cols;
  plan.lines.clear();
  const double lo = std::min(a[along], b[along]);
  const double hi = std::max(a[along], b[along]);
  for (int c = static_cast<int>(std::ceil(lo)); c <= static_cast<int>(std::floor(hi)); ++c) {
    const double t = (c - a[along]) / (b[along] - a[along]);
    if (t * length < margin_px || (1.0 - t) * length < margin_px || c < 0 || c >= c_limit) {
      continue;
    }
    const double crossing = a[plan.scan] + t * (b[plan.scan] - a[plan.scan]);
    const int i0 = static_cast<int>(std::lround(crossing)) - plan.half;
    if (i0 - 1 < 0 || i0 + 2 * plan.half + 1 >= limit) {
      continue;
    }
    plan.lines.emplace_back(c, crossing);
  }
  return static_cast<int>(plan.lines.size()) >= kMinEdgeSamples;
}

double pixel_on(const cv::Mat& gray, const EdgeScan& plan, int c, int i) {
  return plan.scan == 0 ? gray.at<std::uint8_t>(c, i) : gray.at<std::uint8_t>(i, c);
}

Eigen::Vector2d edge_point(const EdgeScan& plan, int c, double position) {
  Eigen::Vector2d point;
  point[plan.scan] = position;
  point[1 - plan.scan] = c;
  return point;
}

}  // namespace

bool locate_marker_edges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, int modules_across,
                         std::array<std::vector<Eigen::Vector2d>, 4>& edge_points) {
  for (int k = 0; k < 4; ++k) {
    edge_points[k].clear();
    EdgeScan plan;
    // Search up to most of a module either way: the only dark-to-light step (going outwards)
    // that close is the marker's own edge; the quiet zone's far edge and the bits step the other way.
    if (!plan_edge_scan(gray, corners, k, modules_across, 0.85, 8.0, plan)) {
      return false;
    }
    const double outwards = plan.white_high ? 1.0 : -1.0;
    for (const auto& [c, crossing] : plan.lines) {
      const int i0 = static_cast<int>(std::lround(crossing)) - plan.half;
      const int i1 = i0 + 2 * plan.half;
      // Step between pixel i and i + 1, signed so that black-to-white outwards is positive.
      int best = -1;
      double best_step = 0.0;
      for (int i = i0; i < i1; ++i) {
        const double step = outwards * (pixel_on(gray, plan, c, i + 1) - pixel_on(gray, plan, c, i));
        if (step > best_step) {
          best_step = step;
          best = i;
        }
      }
      if (best < 0 || best_step < kMinContrast / 4.0) {
        continue;
      }
      // Parabola through the neighbouring steps for a subpixel peak.
      const double before =
          best > i0 ? outwards * (pixel_on(gray, plan, c, best) - pixel_on(gray, plan, c, best - 1)) : 0.0;
      const double after =
          best + 1 < i1 ? outwards * (pixel_on(gray, plan, c, best + 2) - pixel_on(gray, plan, c, best + 1)) : 0.0;
      const double curvature = before - 2.0 * best_step + after;
      const double offset = curvature < 0.0 ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) : 0.0;
      edge_points[k].push_back(edge_point(plan, c, best + 0.5 + offset));
    }
    if (static_cast<int>(edge_points[k].size()) < kMinEdgeSamples) {
      return false;
    }
  }
  return true;
}

bool sample_marker_edges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, int modules_across,
                         std::array<std::vector<Eigen::Vector2d>, 4>& edge_points) {
  for (int k = 0; k < 4; ++k) {
    edge_points[k].clear();
    EdgeScan plan;
    // Short windows hold less noise; kMaxReach leaves room for a blurred (not only antialiased)
    // edge. The window's end pixels give the levels: they must lie beyond the edge's ramp but inside
    // the module on either side even when the window is off-centre by half a pixel.
    if (!plan_edge_scan(gray, corners, k, modules_across, 0.65, kMaxReach_px, plan)) {
      return false;
    }
    std::vector<double> white_levels;
    std::vector<double> black_levels;
    for (const auto& [c, crossing] : plan.lines) {
      const int i0 = static_cast<int>(std::lround(crossing)) - plan.half;
      const int i1 = i0 + 2 * plan.half;
      white_levels.push_back(pixel_on(gray, plan, c, plan.white_high ? i1 : i0));
      black_levels.push_back(pixel_on(gray, plan, c, plan.white_high ? i0 : i1));
    }
    for (std::size_t j = 0; j < plan.lines.size(); ++j) {
      // Local levels, averaged over neighbouring lines (gradual shading along the edge).
      const std::size_t from = j >= kLevelWindow ? j - kLevelWindow : 0;
      const std::size_t to = std::min(plan.lines.size() - 1, j + kLevelWindow);
      double white = 0.0;
      double black = 0.0;
      for (std::size_t q = from; q <= to; ++q) {
        white += white_levels[q];
        black += black_levels[q];
      }
      white /= static_cast<double>(to - from + 1);
      black /= static_cast<double>(to - from + 1);
      if (white - black < kMinContrast) {
        continue;
      }
      const auto& [c, crossing] = plan.lines[j];
      const int i0 = static_cast<int>(std::lround(crossing)) - plan.half;
      const int i1 = i0 + 2 * plan.half;
      double whiteness = 0.0;
      for (int i = i0; i <= i1; ++i) {
        whiteness += (pixel_on(gray, plan, c, i) - black) / (white - black);
      }
      edge_points[k].push_back(edge_point(plan, c, plan.white_high ? i1 + 0.5 - whiteness : i0 - 0.5 + whiteness));
    }
    if (static_cast<int>(edge_points[k].size()) < kMinEdgeSamples) {
      return false;
    }
  }
  return true;
}

bool corners_from_edges(const std::array<std::vector<Eigen::Vector2d>, 4>& edge_points,
                        std::array<Eigen::Vector2d, 4>& corners) {
  std::array<Eigen::Vector3d, 4> lines;
  for (int k = 0; k < 4; ++k) {
    std::vector<Eigen::Vector2d> points = edge_points[k];
    if (static_cast<int>(points.size()) < kMinEdgeSamples) {
      return false;
    }
    Eigen::Vector3d line = fit_line(points);
    // One pass of outlier rejection (a scratch, an occluder's edge, a glint).
    std::vector<double> residuals;
    for (const Eigen::Vector2d& p : points) {
      residuals.push_back(std::abs(line.dot(p.homogeneous())));
    }
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = std::max(0.15, 4.0 * 1.4826 * sorted[sorted.size() / 2]);
    std::vector<Eigen::Vector2d> kept;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (residuals[i] <= limit) {
        kept.push_back(points[i]);
      }
    }
    if (static_cast<int>(kept.size()) < kMinEdgeSamples) {
      return false;
    }
    if (kept.size() != points.size()) {
      line = fit_line(kept);
    }
    lines[k] = line;
  }
  for (int k = 0; k < 4; ++k) {
    // Corner k joins edge k - 1 (corner k-1 -> k) and edge k (corner k -> k+1).
    const Eigen::Vector3d p = lines[(k + 3) % 4].cross(lines[k]);
    if (std::abs(p.z()) < 1e-9) {
      return false;
    }
    corners[k] = p.hnormalized();
  }
  return true;
}

MarkerDetector::MarkerDetector(const DetectorSettings& settings, const CameraIntrinsics& camera)
    : settings_(settings), camera_(camera) {
  if (settings_.dictionary < cv::aruco::DICT_4X4_50 || settings_.dictionary > cv::aruco::DICT_APRILTAG_36h11) {
    throw TrackerConfigError(
        "tracker configuration: detector.dictionary: expected a cv::aruco predefined dictionary id");
  }
  dictionary_ = cv::aruco::getPredefinedDictionary(settings_.dictionary);
  modules_across_ = dictionary_->markerSize + 2;
  parameters_ = cv::aruco::DetectorParameters::create();
  parameters_->useAruco3Detection = settings_.use_aruco3;
  parameters_->minSideLengthCanonicalImg = settings_.min_side_canonical_px;
  parameters_->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  parameters_->cornerRefinementWinSize = 3;
  parameters_->cornerRefinementMinAccuracy = 0.05;
  camera_matrix_ =
      (cv::Mat_<double>(3, 3) << camera_.fx_px, 0, camera_.cx_px, 0, camera_.fy_px, camera_.cy_px, 0, 0, 1);
  // Any of OpenCV's counts (4, 5, 8, 12, 14; validated with the configuration); none: an ideal pinhole.
  distortion_ = cv::Mat(camera_.distortion, true).reshape(1, 1);
  for (const double d : camera_.distortion) distorted_ = distorted_ || d != 0.0;
}

void MarkerDetector::detect_region(const cv::Mat& gray, const cv::Rect& region, double min_marker_side_px,
                                   std::vector<std::vector<cv::Point2f>>& corners, std::vector<int>& ids) {
  const cv::Mat view = gray(region);
  const bool whole_image = region.width == gray.cols && region.height == gray.rows;
  if (whole_image || settings_.region_threshold_window_px == 0) {
    // OpenCV's default sweep of adaptive-threshold windows: robust for markers of any size.
    parameters_->adaptiveThreshWinSizeMin = 3;
    parameters_->adaptiveThreshWinSizeMax = 23;
    parameters_->adaptiveThreshWinSizeStep = 10;
  } else {
    // Around a tracked object the marker size is known: one window suffices (a miss falls back to
    // the full frame), and thresholding plus contour tracing are most of the detector's time.
    parameters_->adaptiveThreshWinSizeMin = settings_.region_threshold_window_px;
    parameters_->adaptiveThreshWinSizeMax = settings_.region_threshold_window_px;
    parameters_->adaptiveThreshWinSizeStep = 1;
  }
  const double longest = std::max(region.width, region.height);
  if (settings_.use_aruco3) {
    // ArUco3 segments an image scaled so that a marker of the smallest side wanted spans
    // minSideLengthCanonicalImg pixels: smallest side = canonical + ratio * longest.
    const double ratio = std::max(0.0, min_marker_side_px - settings_.min_side_canonical_px) / longest;
    parameters_->minMarkerLengthRatioOriginalImg = static_cast<float>(std::min(1.0, ratio));
  } else {
    parameters_->minMarkerPerimeterRate = std::clamp(4.0 * min_marker_side_px / longest, 0.01, 4.0);
  }
  std::vector<std::vector<cv::Point2f>> found;
  std::vector<int> found_ids;
  try {
    cv::aruco::detectMarkers(view, dictionary_, found, found_ids, parameters_);
  } catch (const cv::Exception&) {
    return;  // steady state never throws: a region that upsets the detector yields nothing
  }
  for (std::size_t i = 0; i < found.size(); ++i) {
    for (cv::Point2f& p : found[i]) {
      p.x += static_cast<float>(region.x);
      p.y += static_cast<float>(region.y);
    }
    corners.push_back(std::move(found[i]));
    ids.push_back(found_ids[i]);
  }
}

void MarkerDetector::undistort(std::vector<cv::Point2f>& points) const {
  if (distorted_ && !points.empty()) {
    cv::undistortPoints(std::vector<cv::Point2f>(points), points, camera_matrix_, distortion_, cv::noArray(),
                        camera_matrix_);
  }
}

void MarkerDetector::refine(const cv::Mat& gray, const std::vector<cv::Point2f>& raw, DetectedMarker& marker) const {
  std::vector<cv::Point2f> corners = raw;
  // The detector's corner windows are sized for the image, not the marker: with small modules they
  // reach the quiet zone's far edge and drift by pixels. Re-centre with a window inside one module.
  const double side_px = 0.25 * (cv::norm(raw[0] - raw[1]) + cv::norm(raw[1] - raw[2]) + cv::norm(raw[2] - raw[3]) +
                                 cv::norm(raw[3] - raw[0]));
  const int window = std::clamp(static_cast<int>(0.5 * side_px / modules_across_), 2, 5);
  try {
    cv::cornerSubPix(gray, corners, cv::Size(window, window), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS, 20, 0.01));
  } catch (const cv::Exception&) {
    corners = raw;  // keep the detector's corners
  }
  std::array<Eigen::Vector2d, 4> estimate;
  for (int c = 0; c < 4; ++c) {
    estimate[c] = Eigen::Vector2d(corners[c].x, corners[c].y);
  }
  marker.edge_refined = false;
  if (settings_.refine_edges) {
    std::array<std::vector<Eigen::Vector2d>, 4> edges;
    std::array<Eigen::Vector2d, 4> refined = estimate;
    // Coarse: the steepest step near each edge, robust to corner estimates pixels off. Fine: the
    // area under the edge profile, twice (the second pass centres the windows on the fitted lines).
    bool ok = locate_marker_edges(gray, refined, modules_across_, edges) && corners_from_edges(edges, refined);
    for (int pass = 0; pass < 2 && ok; ++pass) {
      ok = sample_marker_edges(gray, refined, modules_across_, edges) && corners_from_edges(edges, refined);
    }
    if (ok) {
      // A fit that wandered more than a module away latched onto something else.
      for (int c = 0; c < 4; ++c) {
        ok = ok && (refined[c] - estimate[c]).norm() < std::max(2.0, side_px / modules_across_);
      }
    }
    if (ok) {
      if (distorted_) {
        // Lines are straight only without distortion: fit them again to undistorted edge points.
        for (auto& edge : edges) {
          std::vector<cv::Point2f> points;
          for (const Eigen::Vector2d& p : edge) {
            points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
          }
          undistort(points);
          for (std::size_t i = 0; i < points.size(); ++i) {
            edge[i] = Eigen::Vector2d(points[i].x, points[i].y);
          }
        }
        ok = corners_from_edges(edges, refined);
      }
      if (ok) {
        marker.corners_px = refined;
        marker.edge_refined = true;
        return;
      }
    }
  }
  undistort(corners);
  for (int c = 0; c < 4; ++c) {
    marker.corners_px[c] = Eigen::Vector2d(corners[c].x, corners[c].y);
  }
}

std::vector<DetectedMarker> MarkerDetector::detect(const cv::Mat& gray, const std::vector<cv::Rect>& regions,
                                                   double min_marker_side_px) {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  const cv::Rect image(0, 0, gray.cols, gray.rows);
  if (regions.empty()) {
    detect_region(gray, image, min_marker_side_px, corners, ids);
  } else {
    // ArUco3's pyramid needs a region at least twice the canonical marker side.
    const int min_region_px = std::max(16, 2 * settings_.min_side_canonical_px);
    for (const cv::Rect& region : regions) {
      const cv::Rect clipped = region & image;
      if (clipped.width >= min_region_px && clipped.height >= min_region_px) {
        detect_region(gray, clipped, min_marker_side_px, corners, ids);
      }
    }
  }
  // An id seen more than once cannot be told apart: drop it. (Regions do not overlap, so a repeat
  // is a second physical marker or a false decode.)
  std::map<int, int> count;
  for (const int id : ids) {
    ++count[id];
  }
  std::vector<DetectedMarker> markers;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (count[ids[i]] != 1) {
      continue;
    }
    DetectedMarker marker;
    marker.id = ids[i];
    refine(gray, corners[i], marker);
    markers.push_back(marker);
  }
  std::sort(markers.begin(), markers.end(),
            [](const DetectedMarker& a, const DetectedMarker& b) { return a.id < b.id; });
  return markers;
}

}  // namespace rigger::vision
