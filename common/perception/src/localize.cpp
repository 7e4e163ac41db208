#include "rigger/perception/localize.hpp"

#include <opencv2/surface_matching.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mesh_points.hpp"

namespace rigger::perception {

namespace {

using Clock = std::chrono::steady_clock;
using detail::PointIndex;
using detail::SurfacePoints;

// Points per model kept in the distance index: dense enough that point-to-plane distances to the
// nearest sample are exact on flat faces.
constexpr int kDenseModelPoints = 20000;
constexpr int kIcpIterations = 30;
constexpr int kGlobalHypotheses = 8;

struct Scene {
  std::vector<Eigen::Vector3d> points_camera_m;
  std::vector<Eigen::Vector3d> normals_camera;
};

struct Fit {
  Eigen::Isometry3d pose_camera_object = Eigen::Isometry3d::Identity();
  double rms_m = 0.0;
  double inlier_ratio = 0.0;
  int inliers = 0;
};

double rotation_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

}  // namespace

const char* to_string(LocalizeStatus status) {
  switch (status) {
    case LocalizeStatus::kFound: return "FOUND";
    case LocalizeStatus::kNotFound: return "NOT_FOUND";
    case LocalizeStatus::kAmbiguous: return "AMBIGUOUS";
    case LocalizeStatus::kLowFit: return "LOW_FIT";
    case LocalizeStatus::kBadDepth: return "BAD_DEPTH";
    case LocalizeStatus::kNoVisibleSurface: return "NO_VISIBLE_SURFACE";
    case LocalizeStatus::kBadMesh: return "BAD_MESH";
  }
  return "UNKNOWN";
}

struct Localizer::Impl {
  LocalizeOptions options;
  SurfacePoints model;  // sparse: ICP and PPF training
  SurfacePoints dense;  // distances to the surface
  std::unique_ptr<PointIndex> dense_index;
  Eigen::Vector3d centre_object_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  std::vector<Eigen::Isometry3d> symmetries;  // object frame, identity first
  std::vector<Eigen::Matrix3d> symmetry_rotations;
  std::string symmetry_note;
  // A coarse sampling (7 % of the diameter): training is quadratic in the sampled points.
  cv::ppf_match_3d::PPF3DDetector detector{0.07, 0.05, 30};

  double surface_distance(const Eigen::Vector3d& point_object_m) const {
    double d2 = 0.0;
    const int k = dense_index->nearest(point_object_m, d2);
    if (k < 0) {
      return std::sqrt(d2);
    }
    const auto i = static_cast<std::size_t>(k);
    // Point-to-plane near the sample, but never less than the distance across the face's edge.
    const double along_normal = std::abs(dense.normals[i].dot(point_object_m - dense.points_m[i]));
    return std::max(along_normal, std::sqrt(d2) - 0.004);
  }

  void find_symmetries() {
    const std::vector<Eigen::Matrix3d> candidates = {
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix(),
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(),
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
        Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix()};
    const char* names[] = {"2-fold about x", "2-fold about y", "2-fold about z", "4-fold about z"};
    symmetries = {Eigen::Isometry3d::Identity()};
    symmetry_rotations = {Eigen::Matrix3d::Identity()};
    const double tolerance_m = std::max(0.001, 0.01 * radius_m);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      // About the centroid: the symmetry maps the part onto itself where it stands.
      Eigen::Isometry3d s = Eigen::Translation3d(centre_object_m) * Eigen::Isometry3d(candidates[c]) *
                            Eigen::Translation3d(-centre_object_m);
      bool maps = true;
      for (std::size_t i = 0; i < model.points_m.size() && maps; i += 7) {
        maps = surface_distance(s * model.points_m[i]) < tolerance_m;
      }
      if (maps) {
        symmetries.push_back(s);
        symmetry_rotations.push_back(candidates[c]);
        symmetry_note += (symmetry_note.empty() ? "" : ", ") + std::string(names[c]);
      }
    }
  }

  Scene scene_points(const DepthFrame& frame, LocalizeResult& result) const {
    Scene scene;
    const cv::Mat& depth = frame.depth_m;
    const DepthIntrinsics& k = frame.intrinsics;
    if (depth.empty() || depth.type() != CV_32FC1 || !(k.fx_px > 0.0) || !(k.fy_px > 0.0)) {
      result.status = LocalizeStatus::kBadDepth;
      result.message = "depth image empty, not CV_32FC1, or intrinsics without a focal length";
      return scene;
    }
    int finite = 0;
    for (int v = 0; v < depth.rows; ++v) {
      const float* row = depth.ptr<float>(v);
      for (int u = 0; u < depth.cols; ++u) {
        finite += std::isfinite(row[u]) && row[u] > 0.0F ? 1 : 0;
      }
    }
    if (finite == 0) {
      result.status = LocalizeStatus::kBadDepth;
      result.message = "depth image has no finite depth";
      return scene;
    }
    // A pixel grid stride that leaves about four times the points kept (the support is dropped next).
    const int stride = std::max(1, static_cast<int>(std::sqrt(finite / (4.0 * options.max_scene_points))));
    auto point_at = [&](int u, int v, Eigen::Vector3d& p) {
      if (u >= depth.cols || v >= depth.rows) {
        return false;
      }
      const float z = depth.at<float>(v, u);
      if (!std::isfinite(z) || z <= 0.0F) {
        return false;
      }
      p = Eigen::Vector3d((u - k.cx_px) / k.fx_px * z, (v - k.cy_px) / k.fy_px * z, z);
      return true;
    };
    const double max_neighbour_gap_m = 0.02;
    for (int v = 0; v < depth.rows; v += stride) {
      for (int u = 0; u < depth.cols; u += stride) {
        Eigen::Vector3d p;
        Eigen::Vector3d right;
        Eigen::Vector3d down;
        if (!point_at(u, v, p) || !point_at(u + stride, v, right) || !point_at(u, v + stride, down)) {
          continue;
        }
        if ((right - p).norm() > max_neighbour_gap_m || (down - p).norm() > max_neighbour_gap_m) {
          continue;  // a depth edge: no normal to trust
        }
        if (options.min_height_world_m && (frame.pose_world_camera * p).z() <= *options.min_height_world_m) {
          continue;
        }
        Eigen::Vector3d n = (right - p).cross(down - p).normalized();
        if (n.dot(p) > 0.0) {
          n = -n;  // towards the camera
        }
        scene.points_camera_m.push_back(p);
        scene.normals_camera.push_back(n);
      }
    }
    // Evenly thinned to the bound.
    const std::size_t cap = static_cast<std::size_t>(options.max_scene_points);
    if (scene.points_camera_m.size() > cap) {
      Scene thinned;
      const double step = static_cast<double>(scene.points_camera_m.size()) / cap;
      for (std::size_t i = 0; i < cap; ++i) {
        const auto j = static_cast<std::size_t>(i * step);
        thinned.points_camera_m.push_back(scene.points_camera_m[j]);
        thinned.normals_camera.push_back(scene.normals_camera[j]);
      }
      scene = std::move(thinned);
    }
    if (static_cast<int>(scene.points_camera_m.size()) < options.min_supporting_points) {
      result.status = LocalizeStatus::kNoVisibleSurface;
      result.message = "only " + std::to_string(scene.points_camera_m.size()) +
                       " depth points left above the support; at least " +
                       std::to_string(options.min_supporting_points) + " needed";
    }
    return scene;
  }

  // Point-to-plane ICP of the model points facing the camera onto the scene, from `pose`.
  Eigen::Isometry3d refine(const Scene& scene, const PointIndex& scene_index, Eigen::Isometry3d pose) const {
    double reject_m = 0.03;
    for (int iteration = 0; iteration < kIcpIterations; ++iteration) {
      Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      int pairs = 0;
      for (std::size_t i = 0; i < model.points_m.size(); ++i) {
        const Eigen::Vector3d p = pose * model.points_m[i];
        const Eigen::Vector3d n = pose.linear() * model.normals[i];
        if (n.dot(p) >= 0.0) {
          continue;  // facing away: the camera cannot see it
        }
        double d2 = 0.0;
        const int k = scene_index.nearest(p, d2);
        if (k < 0 || d2 > reject_m * reject_m) {
          continue;
        }
        const auto j = static_cast<std::size_t>(k);
        const Eigen::Vector3d& q = scene.points_camera_m[j];
        const Eigen::Vector3d& nq = scene.normals_camera[j];
        if (nq.dot(n) < 0.5) {
          continue;  // a different face
        }
        Eigen::Matrix<double, 6, 1> row;
        row << p.cross(nq), nq;
        a += row * row.transpose();
        b -= row * nq.dot(p - q);
        ++pairs;
      }
      if (pairs < 12) {
        break;
      }
      const Eigen::Matrix<double, 6, 1> x = a.ldlt().solve(b);
      const Eigen::Vector3d w = x.head<3>();
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      if (w.norm() > 0.0) {
        step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      }
      step.translation() = x.tail<3>();
      pose = step * pose;
      reject_m = std::max(0.008, reject_m * 0.7);
      if (w.norm() < 1e-5 && x.tail<3>().norm() < 1e-5) {
        break;
      }
    }
    return pose;
  }

  Fit evaluate(const Scene& scene, const Eigen::Isometry3d& pose_camera_object) const {
    Fit fit;
    fit.pose_camera_object = pose_camera_object;
    const Eigen::Isometry3d object_camera = pose_camera_object.inverse();
    const Eigen::Vector3d centre = pose_camera_object * centre_object_m;
    int near = 0;
    double sum2 = 0.0;
    for (const Eigen::Vector3d& p : scene.points_camera_m) {
      if ((p - centre).norm() > radius_m) {
        continue;
      }
      ++near;
      const double d = surface_distance(object_camera * p);
      if (d <= options.inlier_distance_m) {
        ++fit.inliers;
        sum2 += d * d;
      }
    }
    fit.inlier_ratio = near > 0 ? static_cast<double>(fit.inliers) / near : 0.0;
    fit.rms_m = fit.inliers > 0 ? std::sqrt(sum2 / fit.inliers) : 0.0;
    return fit;
  }

  bool acceptable(const Fit& fit) const {
    return fit.inliers >= options.min_supporting_points && fit.rms_m <= options.max_rms_m &&
           fit.inlier_ratio >= options.min_inlier_ratio;
  }

  // The symmetric equivalent nearest the prior, or without one nearest the world axes.
  Eigen::Isometry3d canonical(const Eigen::Isometry3d& pose_world_object,
                              const std::optional<Eigen::Isometry3d>& prior) const {
    const Eigen::Matrix3d reference = prior ? Eigen::Matrix3d(prior->linear()) : Eigen::Matrix3d::Identity();
    Eigen::Isometry3d best = pose_world_object;
    double best_deg = 1e9;
    for (const Eigen::Isometry3d& s : symmetries) {
      const Eigen::Isometry3d candidate = pose_world_object * s;
      const double deg = rotation_deg(candidate.linear(), reference);
      if (deg < best_deg - 1e-6) {
        best_deg = deg;
        best = candidate;
      }
    }
    return best;
  }

  // Same pose up to the part's symmetries.
  bool equivalent(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const {
    for (const Eigen::Isometry3d& s : symmetries) {
      const Eigen::Isometry3d as = a * s;
      if ((as.translation() - b.translation()).norm() < 0.01 && rotation_deg(as.linear(), b.linear()) < 5.0) {
        return true;
      }
    }
    return false;
  }
};

Localizer::Localizer(const Mesh& mesh, LocalizeOptions options) : impl_(std::make_unique<Impl>()) {
  detail::check_mesh(mesh);
  if (options.max_scene_points < 100 || options.max_model_points < 100) {
    throw std::invalid_argument("perception options: max_scene_points and max_model_points must be at least 100");
  }
  impl_->options = options;
  impl_->model = detail::sample_surface(mesh, options.max_model_points);
  impl_->dense = detail::sample_surface(mesh, kDenseModelPoints);
  if (impl_->model.points_m.empty()) {
    throw std::invalid_argument("perception mesh: all triangles are degenerate (zero area)");
  }
  impl_->dense_index = std::make_unique<PointIndex>(impl_->dense.points_m);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : impl_->dense.points_m) {
    sum += p;
  }
  impl_->centre_object_m = sum / static_cast<double>(impl_->dense.points_m.size());
  for (const Eigen::Vector3d& p : impl_->dense.points_m) {
    impl_->radius_m = std::max(impl_->radius_m, (p - impl_->centre_object_m).norm());
  }
  impl_->radius_m += 0.01;
  impl_->find_symmetries();
  cv::Mat trained(static_cast<int>(impl_->model.points_m.size()), 6, CV_32F);
  for (int i = 0; i < trained.rows; ++i) {
    const auto k = static_cast<std::size_t>(i);
    for (int j = 0; j < 3; ++j) {
      trained.at<float>(i, j) = static_cast<float>(impl_->model.points_m[k][j]);
      trained.at<float>(i, 3 + j) = static_cast<float>(impl_->model.normals[k][j]);
    }
  }
  impl_->detector.trainModel(trained);
}

Localizer::~Localizer() = default;

const std::vector<Eigen::Matrix3d>& Localizer::symmetries() const {
  return impl_->symmetry_rotations;
}

LocalizeResult Localizer::localize(const DepthFrame& frame, const std::optional<Eigen::Isometry3d>& prior_world_object) {
  const Clock::time_point start = Clock::now();
  LocalizeResult result;
  result.symmetry = impl_->symmetry_note;
  auto finish = [&](LocalizeResult& r) {
    r.elapsed = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start);
    return r;
  };
  const Scene scene = impl_->scene_points(frame, result);
  if (result.status == LocalizeStatus::kBadDepth || result.status == LocalizeStatus::kNoVisibleSurface) {
    return finish(result);
  }
  const PointIndex scene_index(scene.points_camera_m);
  const Eigen::Isometry3d camera_world = frame.pose_world_camera.inverse();

  std::vector<Fit> fits;
  if (prior_world_object) {
    const Fit fit = impl_->evaluate(scene, impl_->refine(scene, scene_index, camera_world * *prior_world_object));
    if (impl_->acceptable(fit)) {
      fits.push_back(fit);
    }
  }
  if (fits.empty()) {
    cv::Mat pc(static_cast<int>(scene.points_camera_m.size()), 6, CV_32F);
    for (int i = 0; i < pc.rows; ++i) {
      const auto k = static_cast<std::size_t>(i);
      for (int j = 0; j < 3; ++j) {
        pc.at<float>(i, j) = static_cast<float>(scene.points_camera_m[k][j]);
        pc.at<float>(i, 3 + j) = static_cast<float>(scene.normals_camera[k][j]);
      }
    }
    std::vector<cv::ppf_match_3d::Pose3DPtr> hypotheses;
    impl_->detector.match(pc, hypotheses, 1.0 / 10.0, 0.05);
    for (std::size_t h = 0; h < hypotheses.size() && h < static_cast<std::size_t>(kGlobalHypotheses); ++h) {
      if (Clock::now() - start > impl_->options.time_budget) {
        break;
      }
      Eigen::Matrix4d m;
      for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
          m(r, c) = hypotheses[h]->pose(r, c);
        }
      }
      Eigen::Isometry3d pose(m);
      fits.push_back(impl_->evaluate(scene, impl_->refine(scene, scene_index, pose)));
    }
  }
  if (fits.empty()) {
    result.status = LocalizeStatus::kNotFound;
    result.message = "no pose hypothesis for the part in the depth image";
    return finish(result);
  }
  std::sort(fits.begin(), fits.end(), [](const Fit& a, const Fit& b) { return a.inliers > b.inliers; });
  const Fit& best = fits.front();
  result.pose_world_object = impl_->canonical(frame.pose_world_camera * best.pose_camera_object, prior_world_object);
  result.rms_m = best.rms_m;
  result.inlier_ratio = best.inlier_ratio;
  result.supporting_points = best.inliers;
  if (best.inliers < impl_->options.min_supporting_points) {
    result.status = LocalizeStatus::kNotFound;
    result.message = "best pose has " + std::to_string(best.inliers) + " supporting points; at least " +
                     std::to_string(impl_->options.min_supporting_points) + " needed";
    return finish(result);
  }
  if (!impl_->acceptable(best)) {
    result.status = LocalizeStatus::kLowFit;
    result.message = "best pose fits with rms " + std::to_string(best.rms_m * 1000.0) + " mm, inlier ratio " +
                     std::to_string(best.inlier_ratio);
    return finish(result);
  }
  for (std::size_t i = 1; i < fits.size(); ++i) {
    const Fit& other = fits[i];
    if (impl_->acceptable(other) && other.inliers >= 0.97 * best.inliers &&
        !impl_->equivalent(best.pose_camera_object, other.pose_camera_object)) {
      result.status = LocalizeStatus::kAmbiguous;
      result.message = "two poses that are not symmetric equivalents fit equally well (" +
                       std::to_string(best.inliers) + " and " + std::to_string(other.inliers) + " points)";
      return finish(result);
    }
  }
  result.status = LocalizeStatus::kFound;
  return finish(result);
}

}  // namespace rigger::perception
