#include "pose_estimator.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>
#include <cmath>

namespace rigger::vision {
namespace {

// Mirror solutions whose reprojection errors are within this ratio are ambiguous.
constexpr double kAmbiguityRatio = 1.5;
// Two starts refined to poses this close in rotation are one solution, not a mirror pair: IPPE's second
// start often refines onto the first (a large layout seen at a moderate angle, or one facing the camera).
constexpr double kSameSolutionRad = 1.0 * M_PI / 180.0;
constexpr double kCoplanarTolerance_m = 1e-6;
constexpr int kMaxRefineIterations = 10;

Eigen::Isometry3d to_isometry(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rotation;
  cv::cv2eigen(r, rotation);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return pose;
}

Eigen::Matrix3d small_rotation(const Eigen::Vector3d& angle_axis) {
  const double angle = angle_axis.norm();
  if (angle < 1e-15) {
    return Eigen::Matrix3d::Identity();
  }
  return Eigen::AngleAxisd(angle, angle_axis / angle).toRotationMatrix();
}

struct Candidate {
  Eigen::Isometry3d pose;
  double rms_px;
};

}  // namespace

std::array<Eigen::Vector3d, 4> marker_corners_object(const MarkerPlacement& marker) {
  const double h = 0.5 * marker.size_m;
  return {marker.pose_object_marker * Eigen::Vector3d(-h, h, 0), marker.pose_object_marker * Eigen::Vector3d(h, h, 0),
          marker.pose_object_marker * Eigen::Vector3d(h, -h, 0),
          marker.pose_object_marker * Eigen::Vector3d(-h, -h, 0)};
}

double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

PoseEstimator::PoseEstimator(const CameraIntrinsics& camera, const EstimatorSettings& settings)
    : camera_(camera), settings_(settings) {}

Eigen::Vector2d PoseEstimator::project(const Eigen::Isometry3d& pose, const Eigen::Vector3d& point) const {
  const Eigen::Vector3d p = pose * point;
  return camera_.project(p);
}

void PoseEstimator::normal_equations(const std::vector<Eigen::Vector3d>& object_points,
                                     const std::vector<Eigen::Vector2d>& image_points, const Eigen::Isometry3d& pose,
                                     Eigen::Matrix<double, 6, 6>& jtj, Eigen::Matrix<double, 6, 1>& jtr) const {
  jtj.setZero();
  jtr.setZero();
  for (std::size_t i = 0; i < object_points.size(); ++i) {
    const Eigen::Vector3d rotated = pose.linear() * object_points[i];
    const Eigen::Vector3d p = rotated + pose.translation();
    const double inv_z = 1.0 / p.z();
    Eigen::Matrix<double, 2, 3> d_projection;
    d_projection << camera_.fx_px * inv_z, 0.0, -camera_.fx_px * p.x() * inv_z * inv_z,  //
        0.0, camera_.fy_px * inv_z, -camera_.fy_px * p.y() * inv_z * inv_z;
    // p(t + dt, exp(dtheta) R) = p + dt - [R X]x dtheta.
    Eigen::Matrix<double, 3, 6> d_point;
    d_point.leftCols<3>() = Eigen::Matrix3d::Identity();
    d_point.rightCols<3>() << 0.0, rotated.z(), -rotated.y(),  //
        -rotated.z(), 0.0, rotated.x(),                        //
        rotated.y(), -rotated.x(), 0.0;
    const Eigen::Matrix<double, 2, 6> j = d_projection * d_point;
    const Eigen::Vector2d residual = camera_.project(p) - image_points[i];
    jtj += j.transpose() * j;
    jtr += j.transpose() * residual;
  }
}

bool PoseEstimator::refine(const std::vector<Eigen::Vector3d>& object_points,
                           const std::vector<Eigen::Vector2d>& image_points, Eigen::Isometry3d& pose) const {
  // Gauss-Newton on the reprojection error from a closed-form start (IPPE/SQPnP): converges in a
  // few steps; the analytic Jacobian is the one the covariance uses.
  for (int iteration = 0; iteration < kMaxRefineIterations; ++iteration) {
    Eigen::Matrix<double, 6, 6> jtj;
    Eigen::Matrix<double, 6, 1> jtr;
    normal_equations(object_points, image_points, pose, jtj, jtr);
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(jtj);
    if (ldlt.info() != Eigen::Success) {
      return false;
    }
    const Eigen::Matrix<double, 6, 1> step = -ldlt.solve(jtr);
    if (!step.allFinite()) {
      return false;
    }
    pose.translation() += step.head<3>();
    pose.linear() = small_rotation(step.tail<3>()) * pose.linear();
    if (step.head<3>().norm() < 1e-9 && step.tail<3>().norm() < 1e-9) {
      break;
    }
  }
  for (const Eigen::Vector3d& p : object_points) {
    if (!((pose * p).z() > 0.0)) {
      return false;
    }
  }
  return true;
}

EstimateStatus PoseEstimator::estimate(const ObjectLayout& layout, const std::vector<DetectedMarker>& markers,
                                       const std::optional<Eigen::Isometry3d>& prior, PoseEstimate& out) const {
  std::vector<Eigen::Vector3d> object_points;
  std::vector<Eigen::Vector2d> image_points;
  std::vector<const MarkerPlacement*> used;
  for (const DetectedMarker& detected : markers) {
    const auto it = std::find_if(layout.markers.begin(), layout.markers.end(),
                                 [&](const MarkerPlacement& m) { return m.id == detected.id; });
    if (it == layout.markers.end()) {
      continue;
    }
    used.push_back(&*it);
    const auto corners = marker_corners_object(*it);
    for (int c = 0; c < 4; ++c) {
      object_points.push_back(corners[c]);
      image_points.push_back(detected.corners_px[c]);
    }
  }
  if (used.empty()) {
    return EstimateStatus::kNoMarkers;
  }

  const Eigen::Vector3d plane_normal = used.front()->pose_object_marker.linear().col(2);
  const Eigen::Vector3d plane_point = used.front()->pose_object_marker.translation();
  bool coplanar = true;
  for (const Eigen::Vector3d& p : object_points) {
    coplanar = coplanar && std::abs((p - plane_point).dot(plane_normal)) < kCoplanarTolerance_m;
  }

  // IPPE is given a planar layout in its plane's own frame (z = 0 there): a plane that does not pass
  // through the object's origin, or is not normal to its z, gives it wrong poses.
  Eigen::Isometry3d pose_object_plane = Eigen::Isometry3d::Identity();
  if (coplanar) {
    const Eigen::Vector3d helper = std::abs(plane_normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d x = (helper - helper.dot(plane_normal) * plane_normal).normalized();
    pose_object_plane.linear().col(0) = x;
    pose_object_plane.linear().col(1) = plane_normal.cross(x);
    pose_object_plane.linear().col(2) = plane_normal;
    pose_object_plane.translation() = plane_point;
  }
  const Eigen::Isometry3d pose_plane_object = pose_object_plane.inverse();
  std::vector<cv::Point3d> cv_object;
  std::vector<cv::Point2d> cv_image;
  for (std::size_t i = 0; i < object_points.size(); ++i) {
    const Eigen::Vector3d q = pose_plane_object * object_points[i];
    cv_object.emplace_back(q.x(), q.y(), q.z());
    cv_image.emplace_back(image_points[i].x(), image_points[i].y());
  }
  const cv::Mat k =
      (cv::Mat_<double>(3, 3) << camera_.fx_px, 0, camera_.cx_px, 0, camera_.fy_px, camera_.cy_px, 0, 0, 1);
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  try {
    // IPPE returns both mirror solutions of a planar layout; SQPnP the global optimum otherwise.
    cv::solvePnPGeneric(cv_object, cv_image, k, cv::noArray(), rvecs, tvecs, false,
                        coplanar ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_SQPNP);
  } catch (const cv::Exception&) {
    return EstimateStatus::kFailed;
  }
  const auto rms_of = [&](const Eigen::Isometry3d& pose) {
    double sum = 0.0;
    for (std::size_t i = 0; i < object_points.size(); ++i) {
      sum += (project(pose, object_points[i]) - image_points[i]).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(object_points.size()));
  };
  std::vector<Candidate> candidates;
  for (std::size_t s = 0; s < rvecs.size(); ++s) {
    cv::Mat rvec;
    cv::Mat tvec;
    rvecs[s].convertTo(rvec, CV_64F);
    tvecs[s].convertTo(tvec, CV_64F);
    Eigen::Isometry3d pose = to_isometry(rvec, tvec) * pose_plane_object;
    bool in_front = pose.matrix().allFinite();
    for (const Eigen::Vector3d& p : object_points) {
      in_front = in_front && (pose * p).z() > 0.0;
    }
    if (in_front && refine(object_points, image_points, pose)) {
      candidates.push_back({pose, rms_of(pose)});
    }
  }
  if (candidates.empty()) {
    return EstimateStatus::kFailed;
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.rms_px < b.rms_px; });
  if (candidates.size() > 1 &&
      rotation_angle_between(candidates[0].pose.linear(), candidates[1].pose.linear()) < kSameSolutionRad) {
    candidates.erase(candidates.begin() + 1);
  }
  Candidate best = candidates.front();
  out.ambiguous = candidates.size() > 1 && candidates[1].rms_px < kAmbiguityRatio * std::max(best.rms_px, 1e-3);
  if (out.ambiguous && prior) {
    const auto distance_to_prior = [&](const Candidate& c) {
      return rotation_angle_between(prior->linear(), c.pose.linear());
    };
    if (distance_to_prior(candidates[1]) < distance_to_prior(best)) {
      best = candidates[1];
    }
  }
  out.pose_camera_object = best.pose;
  out.reprojection_rms_px = best.rms_px;
  out.markers_used = static_cast<int>(used.size());

  // Quality: how well the model fits, how much of the layout was seen, how squarely.
  const auto ramp = [](double x, double full, double zero) { return std::clamp((zero - x) / (zero - full), 0.0, 1.0); };
  const double good = settings_.good_viewing_angle_deg * M_PI / 180.0;
  const double grazing = settings_.grazing_viewing_angle_deg * M_PI / 180.0;
  double angle_factor = 0.0;
  out.max_viewing_angle_rad = 0.0;
  for (const MarkerPlacement* marker : used) {
    const Eigen::Isometry3d pose_camera_marker = best.pose * marker->pose_object_marker;
    const Eigen::Vector3d centre = pose_camera_marker.translation();
    const double cosine = -pose_camera_marker.linear().col(2).dot(centre) / centre.norm();
    const double angle = std::acos(std::clamp(cosine, -1.0, 1.0));
    out.max_viewing_angle_rad = std::max(out.max_viewing_angle_rad, angle);
    angle_factor += ramp(angle, good, grazing);
  }
  angle_factor /= static_cast<double>(used.size());
  const double fit_factor = std::exp(-std::pow(best.rms_px / settings_.quality_reprojection_scale_px, 2));
  const double share_factor = std::sqrt(static_cast<double>(used.size()) / static_cast<double>(layout.markers.size()));
  out.quality = std::clamp(fit_factor * share_factor * angle_factor * (out.ambiguous ? 0.5 : 1.0), 0.0, 1.0);

  // Covariance: sigma^2 (J^T J)^-1, J the reprojection Jacobian for perturbations of the position
  // and a small rotation on the left (camera axes, about the object origin).
  Eigen::Matrix<double, 6, 6> information;
  Eigen::Matrix<double, 6, 1> unused;
  normal_equations(object_points, image_points, best.pose, information, unused);
  const double n = static_cast<double>(object_points.size());
  const double dof = 2.0 * n - 6.0;
  const double residual_variance = dof > 0.0 ? best.rms_px * best.rms_px * n / dof : 0.0;
  const double variance = std::max(residual_variance, settings_.min_pixel_sigma_px * settings_.min_pixel_sigma_px);
  const Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(information);
  out.covariance_camera = lu.isInvertible()
                              ? Eigen::Matrix<double, 6, 6>(variance * lu.inverse())
                              : Eigen::Matrix<double, 6, 6>(Eigen::Matrix<double, 6, 6>::Identity() * 1e6);

  if (best.rms_px > settings_.max_reprojection_rms_px) {
    return EstimateStatus::kReprojectionTooLarge;
  }
  if (out.quality < settings_.min_quality) {
    return EstimateStatus::kLowQuality;
  }
  return EstimateStatus::kOk;
}

}  // namespace rigger::vision
