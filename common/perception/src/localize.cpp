#include "rigger/perception/localize.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "depth_grid.hpp"
#include "face_directions.hpp"
#include "mesh_points.hpp"
#include "turns.hpp"
#include "visibility.hpp"

namespace rigger::perception {

namespace {

using Clock = std::chrono::steady_clock;
using detail::DepthGrid;
using detail::kSquarelyFacing;
using detail::PointIndex;
using detail::Surface;
using detail::SurfaceIndex;
using detail::SurfacePoints;
using detail::visibility_score;

// Points per model kept for surface distances: about 4 mm apart on the demo load, so that the
// distance to the nearest few samples' planes is exact to a fraction of a millimetre.
constexpr int kDenseModelPoints = 20000;
// Points of the model scored for every sampled orientation, and refined from the best few.
constexpr int kCoarseModelPoints = 160;
// Grid cells of the depth image (a pixel stride of 2 for 1280 x 720).
constexpr int kGridCells = 250000;
// The image's dominant face directions matched (each holding this share of its normals, at most this many),
// and the model's.
constexpr double kImageFaceShare = 0.05;
constexpr int kImageFaces = 3;
constexpr double kModelFaceShare = 0.03;
constexpr int kModelFaces = 12;
// With one face direction matched, turns about it tried.
constexpr int kFaceTurns = 36;
// Without a dominant face: orientations tried, directions of the object's z axis in the camera, times turns about it
// (about 18 degrees apart each way: inside the basin of the refinement).
constexpr int kDirections = 128;
constexpr int kTurns = 20;
// Orientations refined coarsely, then fully (past the best, only those scoring this share of it after the
// coarse refinement: no answer of the bench or the table test changed, the bracket's search took a third less).
constexpr int kCoarseRefined = 24;
constexpr int kFullyRefined = 5;
constexpr double kFullyRefinedScore = 0.5;
// Surfaces of the image tried, largest first.
constexpr int kSurfacesTried = 3;
// A pose of the search is refused when more of its squarely facing surface than this lands on no depth.
constexpr double kMaxUnseen = 0.05;
// ... or more than this is behind nearer depth (correct poses of the bench's parts: at most 0.16; an L bracket
// with its legs swapped, fitted behind the face it was fitted to: 0.33) ...
constexpr double kMaxHidden = 0.25;
// ... or reaches this far below the height under which the image's points are support.
constexpr double kThroughSupportM = 0.03;
// With a prior: how far the part may be from it (its box grown by this holds the points it is refined
// on), and the margin of its box within which the image's points are judged (twice the inlier distance).
constexpr double kPriorOffM = 0.04;
constexpr double kJudgedMarginM = 0.01;

struct Fit {
  Eigen::Isometry3d pose_camera_object = Eigen::Isometry3d::Identity();
  double score = 0.0;
  double rms_m = 0.0;
  double inlier_ratio = 0.0;
  double model_support = 0.0;
  double worst_direction_ratio = 0.0;
  int inliers = 0;
  // Of the camera-facing surface seen within 70 degrees of its normal, the shares that land where the image
  // has no depth and behind something nearer (weighted by how squarely it faces): judged for the search's
  // poses only.
  double unseen = 0.0;
  double hidden = 0.0;
  bool searched = false;
  // How far the part reaches below the support's height (world), when it is known: a search's pose through the
  // support (a bracket's upright down through the table, which hides it) is no pose.
  double below_support_m = 0.0;
};

// Weight of the point-to-point residual next to the point-to-plane one in the final refinement.
constexpr double kPointToPoint = 0.2;
// How far, and in what steps, a pose is slid along the direction its refinement fixes least.
constexpr double kSlideM = 0.06;
constexpr double kSlideStepM = 0.002;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

double rotation_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

}  // namespace

struct Localizer::Impl {
  LocalizeOptions options;
  SurfacePoints model;   // refinement and the model-side check
  SurfacePoints coarse;  // scoring of every sampled orientation
  SurfacePoints dense;   // distances to the surface
  std::unique_ptr<PointIndex> dense_index;
  double dense_spacing_m = 0.0;  // between neighbouring dense samples
  Eigen::Vector3d centre_object_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  Eigen::Vector3d box_low_m = Eigen::Vector3d::Zero();  // the part's bounding box, object frame
  Eigen::Vector3d box_high_m = Eigen::Vector3d::Zero();
  std::vector<Eigen::Isometry3d> symmetries;  // object frame, identity first
  std::vector<Eigen::Matrix3d> symmetry_rotations;
  std::string symmetry_note;
  std::vector<Eigen::Matrix3d> orientations = detail::orientation_samples(kDirections, kTurns);
  std::vector<detail::FaceDirection> model_faces;  // object frame

  // Distance to the surface: to the nearest samples' tangent planes, never less than the distance to
  // the sample less the sampling's spacing (so that the plane of a face does not reach past its edge).
  double surface_distance(const Eigen::Vector3d& point_object_m) const {
    int k[4];
    double d2[4];
    const int found = dense_index->nearest(point_object_m, 4, k, d2);
    double best = std::numeric_limits<double>::infinity();  // farther than a cell from every sample
    for (int i = 0; i < found; ++i) {
      const auto j = static_cast<std::size_t>(k[i]);
      const double along_normal = std::abs(dense.normals[j].dot(point_object_m - dense.points_m[j]));
      best = std::min(best, std::max(along_normal, std::sqrt(d2[i]) - dense_spacing_m));
    }
    return best;
  }

  // The model's face directions, found when first searched for (a fit from a prior needs none).
  void find_model_faces() {
    if (!model_faces.empty()) {
      return;
    }
    SurfacePoints some;
    for (std::size_t i = 0; i < dense.points_m.size(); i += 10) {
      some.points_m.push_back(dense.points_m[i]);
      some.normals.push_back(dense.normals[i]);
    }
    model_faces = detail::face_directions(some.points_m, some.normals, kModelFaceShare, kModelFaces);
  }

  void find_symmetries() {
    symmetries = {Eigen::Isometry3d::Identity()};
    symmetry_rotations = {Eigen::Matrix3d::Identity()};
    const auto distance = [this](const Eigen::Vector3d& p) { return surface_distance(p); };
    for (const detail::Turn& turn :
         detail::turns_onto_itself(model, distance, centre_object_m, std::max(0.001, 0.01 * radius_m))) {
      symmetries.push_back(turn.about_centre);
      symmetry_rotations.push_back(turn.rotation);
      symmetry_note += (symmetry_note.empty() ? "" : ", ") + turn.name;
    }
  }

  // Point-to-plane ICP of the points facing the camera onto the depth image. Without `nearest`,
  // each point is paired with the image cell it projects to (a pixel lookup: fast, but slow to
  // slide along a face); with it, with the nearest cell of the surface it indexes (exact to the end).
  // `translation_only`: the orientation is kept, the position alone refined.
  static Eigen::Isometry3d refine(const DepthGrid& grid, const SurfacePoints& points, Eigen::Isometry3d pose,
                                  int iterations, double final_reject_m, const SurfaceIndex* nearest = nullptr,
                                  Eigen::Matrix3d* translation_information = nullptr, bool translation_only = false) {
    // Wide at first: a face seen at a grazing angle may be the only one that fixes the pose along
    // the others' common edge, and starts as far from its match as the pose is off.
    double reject_m = 0.04;
    for (int iteration = 0; iteration < iterations; ++iteration) {
      Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      int pairs = 0;
      for (std::size_t i = 0; i < points.points_m.size(); ++i) {
        const Eigen::Vector3d p = pose * points.points_m[i];
        const Eigen::Vector3d n = pose.linear() * points.normals[i];
        if (n.dot(p) >= 0.0) {
          continue;  // facing away: the camera cannot see it
        }
        int cell = grid.cell_of(p);
        if (cell < 0 || !std::isfinite(grid.seen_z(cell))) {
          continue;  // out of view, or nothing seen there: no evidence either way
        }
        if (nearest) {
          // No test of what hides the point: a grazing face off by a centimetre along its normal is
          // several centimetres off along the ray, behind the face it should be paired with.
          int k = 0;
          double d2 = 0.0;
          if (nearest->index.nearest(p, 1, &k, &d2) == 0) {
            continue;
          }
          cell = nearest->cells[static_cast<std::size_t>(k)];
        } else if (!grid.valid(cell)) {
          continue;
        }
        const Eigen::Vector3d& q = grid.point(cell);
        const Eigen::Vector3d& nq = grid.normal(cell);
        if ((p - q).squaredNorm() > reject_m * reject_m || nq.dot(n) < 0.6) {
          continue;  // hidden behind another surface, or a different face
        }
        Eigen::Matrix<double, 6, 1> row;
        // Paired with the nearest point, against the model's plane: the model's normal is exact, the
        // image's is the difference of noisy depths a few pixels apart (millimetres of noise at a metre
        // and a half) and would tilt the pose. Paired along the ray (from further off), against the
        // image's: its plane stops a point on the wrong face from dragging the pose along it.
        const Eigen::Vector3d& plane = nearest ? n : nq;
        row << p.cross(plane), plane;
        a += row * row.transpose();
        b -= row * plane.dot(p - q);
        if (nearest) {
          // A little point-to-point as well: where only two faces are seen, nothing in their planes
          // stops the part sliding along their edge, but the points past the end of a face pull back.
          Eigen::Matrix<double, 3, 6> jacobian;
          jacobian << -skew(p), Eigen::Matrix3d::Identity();
          a += kPointToPoint * jacobian.transpose() * jacobian;
          b -= kPointToPoint * jacobian.transpose() * (p - q);
        }
        ++pairs;
      }
      if (pairs < 12) {
        break;
      }
      if (translation_information) {
        *translation_information = a.bottomRightCorner<3, 3>();
      }
      Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
      if (translation_only) {
        x.tail<3>() = a.bottomRightCorner<3, 3>().ldlt().solve(b.tail<3>());
      } else {
        x = a.ldlt().solve(b);
      }
      const Eigen::Vector3d w = x.head<3>();
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      if (w.norm() > 0.0) {
        step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      }
      step.translation() = x.tail<3>();
      pose = step * pose;
      reject_m = std::max(final_reject_m, reject_m * (nearest ? 0.85 : 0.7));
      if (w.norm() < 2e-5 && x.tail<3>().norm() < 2e-5 && reject_m <= final_reject_m) {
        break;
      }
    }
    return pose;
  }

  // The pose along the direction the refinement fixes least (two faces seen: their common edge), at
  // the offset whose camera-facing points the image sees best: points past the end of a face are
  // seen through, so only the true offset (the middle of a plateau that the image's eroded edges
  // leave) has none.
  // Any depth at a point's distance counts (not only cells with a normal): else a face's last millimetres,
  // where normals end, weigh as the holes past its end, and the plateau reaches into a grazing face's holes.
  Eigen::Isometry3d slide(const DepthGrid& grid, const Eigen::Isometry3d& pose,
                          const Eigen::Matrix3d& information) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(information);
    if (eigen.info() != Eigen::Success || eigen.eigenvalues()(0) > 0.5 * eigen.eigenvalues()(2)) {
      return pose;  // no direction fixed less than half as well as the best
    }
    const Eigen::Vector3d direction = eigen.eigenvectors().col(0);
    // The dense samples of the faces seen squarely: the refinement's are about 2 cm apart on a face of
    // the demo load, so that its score changes only as a whole row of them crosses an edge.
    SurfacePoints squarely;
    for (std::size_t i = 0; i < dense.points_m.size(); ++i) {
      const Eigen::Vector3d p = pose * dense.points_m[i];
      if (-(pose.linear() * dense.normals[i]).dot(p) > kSquarelyFacing * p.norm()) {
        squarely.points_m.push_back(dense.points_m[i]);
        squarely.normals.push_back(dense.normals[i]);
      }
    }
    const int steps = static_cast<int>(std::ceil(kSlideM / kSlideStepM));
    double best = -1e18;
    int first_best = 0;
    int last_best = 0;
    for (int i = -steps; i <= steps; ++i) {
      const Eigen::Isometry3d moved = Eigen::Translation3d(i * kSlideStepM * direction) * pose;
      const double score = visibility_score(grid, squarely, moved, nullptr, nullptr, true);
      if (score > best + 0.5) {
        best = score;
        first_best = last_best = i;
      } else if (score > best - 0.5 && last_best == i - 1) {
        last_best = i;
      }
    }
    return Eigen::Translation3d(0.5 * (first_best + last_best) * kSlideStepM * direction) * pose;
  }

  // From a coarse pose to the final one: projective ICP, nearest-point ICP, a slide along the
  // direction that fixes least, and nearest-point ICP again, of the whole pose or of its position alone,
  // whichever fits the image's points better: re-paired after the slide, the points across a slid edge
  // may tilt a part seen nearly face-on (the demo load), while another part's orientation still gains
  // from the whole pose (the bracket).
  Eigen::Isometry3d finish(const DepthGrid& grid, const SurfaceIndex& nearest, const Eigen::Isometry3d& start) const {
    const Eigen::Isometry3d close = refine(grid, model, start, 10, 0.015);
    Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
    const Eigen::Isometry3d fine = refine(grid, model, close, 20, 0.006, &nearest, &information);
    const Eigen::Isometry3d slid = slide(grid, fine, information);
    const Eigen::Isometry3d whole = refine(grid, model, slid, 10, 0.006, &nearest);
    const Eigen::Isometry3d placed_only = refine(grid, model, slid, 10, 0.006, &nearest, nullptr, true);
    return evaluate(grid, nearest.cells, placed_only).score > evaluate(grid, nearest.cells, whole).score ? placed_only
                                                                                                         : whole;
  }

  // Judges a refined pose: from the image side (of the points of the surface searched, how many lie
  // on the part's surface: a surface is searched only when no wider than the part, so it should be
  // the part alone) and from the model side (of its points facing the camera, how many the image sees
  // rather than sees through).
  Fit evaluate(const DepthGrid& grid, const std::vector<int>& cells,
               const Eigen::Isometry3d& pose_camera_object) const {
    Fit fit;
    fit.pose_camera_object = pose_camera_object;
    const Eigen::Isometry3d object_camera = pose_camera_object.inverse();
    const double step = std::max(1.0, static_cast<double>(cells.size()) / options.max_scene_points);
    int near = 0;
    double sum2 = 0.0;
    // Per direction of the normal in the object's frame (its dominant axis and sign): a face seen
    // at a grazing angle is few points of the whole, but the only ones that fix the pose along the
    // other faces' common edge; a pose off along it leaves that face alone unexplained.
    int direction_near[6] = {0, 0, 0, 0, 0, 0};
    int direction_inliers[6] = {0, 0, 0, 0, 0, 0};
    for (double at = 0.0; at < static_cast<double>(cells.size()); at += step) {
      const int cell = cells[static_cast<std::size_t>(at)];
      const Eigen::Vector3d& p = grid.point(cell);
      ++near;
      const Eigen::Vector3d n = object_camera.linear() * grid.normal(cell);
      int axis = 0;
      n.cwiseAbs().maxCoeff(&axis);
      const int direction = 2 * axis + (n[axis] > 0.0 ? 1 : 0);
      ++direction_near[direction];
      const double d = surface_distance(object_camera * p);
      if (d <= options.inlier_distance_m) {
        ++fit.inliers;
        ++direction_inliers[direction];
        sum2 += d * d;
      }
    }
    fit.inlier_ratio = near > 0 ? static_cast<double>(fit.inliers) / near : 0.0;
    fit.worst_direction_ratio = 1.0;
    for (int d = 0; d < 6; ++d) {
      if (direction_near[d] >= std::max(20, near / 50)) {
        fit.worst_direction_ratio =
            std::min(fit.worst_direction_ratio, static_cast<double>(direction_inliers[d]) / direction_near[d]);
      }
    }
    fit.rms_m = fit.inliers > 0 ? std::sqrt(sum2 / fit.inliers) : 0.0;
    int supported = 0;
    int seen_through = 0;
    visibility_score(grid, model, pose_camera_object, &supported, &seen_through);
    fit.model_support =
        supported + seen_through > 0 ? static_cast<double>(supported) / (supported + seen_through) : 0.0;
    const detail::FacingShares shares = detail::facing_shares(grid, model, pose_camera_object);
    fit.unseen = shares.unseen;
    fit.hidden = shares.hidden;
    // The image's points alone do not tell a part from the same part slid along an edge of two seen
    // faces (both explain every point); the points it sees through do.
    fit.score = fit.inliers * fit.model_support * fit.model_support;
    return fit;
  }

  // A pose of the search slid off the part into the image's holes (the void behind a hanging part, a face
  // seen edge-on) explains every point it is judged on; the surface it puts where nothing is seen does not.
  bool acceptable(const Fit& fit) const {
    return !(fit.searched &&
             (fit.unseen > kMaxUnseen || fit.hidden > kMaxHidden || fit.below_support_m > kThroughSupportM)) &&
           fit.inliers >= options.min_supporting_points && fit.rms_m <= options.max_rms_m &&
           fit.inlier_ratio >= options.min_inlier_ratio && fit.model_support >= options.min_model_support &&
           fit.worst_direction_ratio >= options.min_direction_ratio;
  }

  // Candidate poses (from the faces seen or, without a dominant face, every sampled orientation placed on
  // the surface) scored; the best refined coarsely, rescored, and the best of those refined fully and judged.
  void search(const DepthGrid& grid, const Surface& surface, std::vector<Fit>& fits) const {
    std::vector<std::pair<double, Eigen::Isometry3d>> scored;
    for (const Eigen::Isometry3d& pose :
         detail::face_hypotheses(grid, surface, model_faces, coarse, kImageFaceShare, kImageFaces, kFaceTurns)) {
      scored.emplace_back(visibility_score(grid, coarse, pose), pose);
    }
    if (scored.empty()) {
      scored.reserve(orientations.size());
      for (const Eigen::Matrix3d& rotation : orientations) {
        const Eigen::Isometry3d pose = detail::placed(coarse, rotation, surface.centroid_m);
        scored.emplace_back(visibility_score(grid, coarse, pose), pose);
      }
    }
    auto by_score = [](const auto& a, const auto& b) { return a.first > b.first; };
    const auto keep = std::min(scored.size(), static_cast<std::size_t>(kCoarseRefined));
    std::partial_sort(scored.begin(), scored.begin() + static_cast<std::ptrdiff_t>(keep), scored.end(), by_score);
    scored.resize(keep);
    for (auto& [score, pose] : scored) {
      pose = refine(grid, coarse, pose, 8, 0.015);
      score = visibility_score(grid, coarse, pose);
    }
    std::sort(scored.begin(), scored.end(), by_score);
    std::vector<Eigen::Isometry3d> refined;
    for (const auto& [score, pose] : scored) {
      if (static_cast<int>(refined.size()) >= kFullyRefined ||
          (!refined.empty() && score < kFullyRefinedScore * scored.front().first)) {
        break;
      }
      const bool seen = std::any_of(refined.begin(), refined.end(),
                                    [&](const Eigen::Isometry3d& other) { return equivalent(pose, other); });
      if (!seen) {
        refined.push_back(pose);
      }
    }
    const SurfaceIndex nearest(grid, surface);
    for (const Eigen::Isometry3d& pose : refined) {
      fits.push_back(evaluate(grid, surface.cells, finish(grid, nearest, pose)));
      fits.back().searched = true;
    }
  }

  // The image's points within the part's box at `pose_camera_object` grown by `margin_m`.
  Surface cropped(const DepthGrid& grid, const std::vector<Surface>& surfaces,
                  const Eigen::Isometry3d& pose_camera_object, double margin_m) const {
    return detail::within_box(grid, surfaces, pose_camera_object.inverse(), box_low_m.array() - margin_m,
                              box_high_m.array() + margin_m);
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
  impl_->coarse = detail::sample_surface(mesh, kCoarseModelPoints);
  impl_->dense = detail::sample_surface(mesh, kDenseModelPoints);
  if (impl_->model.points_m.empty()) {
    throw std::invalid_argument("perception mesh: all triangles are degenerate (zero area)");
  }
  impl_->dense_spacing_m = std::sqrt(detail::surface_area(mesh) / kDenseModelPoints);
  impl_->dense_index = std::make_unique<PointIndex>(impl_->dense.points_m, 3.0 * impl_->dense_spacing_m);
  // The exact centroid of the surface (not of the samples): a symmetry turns about it.
  impl_->centre_object_m = detail::surface_centroid(mesh);
  for (const Eigen::Vector3d& p : impl_->dense.points_m) {
    impl_->radius_m = std::max(impl_->radius_m, (p - impl_->centre_object_m).norm());
  }
  impl_->radius_m += 0.01;
  impl_->box_low_m = impl_->box_high_m = impl_->dense.points_m.front();
  for (const Eigen::Vector3d& p : impl_->dense.points_m) {
    impl_->box_low_m = impl_->box_low_m.cwiseMin(p);
    impl_->box_high_m = impl_->box_high_m.cwiseMax(p);
  }
  impl_->find_symmetries();
}

Localizer::~Localizer() = default;

const std::vector<Eigen::Matrix3d>& Localizer::symmetries() const {
  return impl_->symmetry_rotations;
}

LocalizeResult Localizer::localize(const DepthFrame& frame,
                                   const std::optional<Eigen::Isometry3d>& prior_world_object) {
  const Clock::time_point start = Clock::now();
  LocalizeResult result;
  result.symmetry = impl_->symmetry_note;
  auto finish = [&](LocalizeStatus status, std::string message) {
    result.status = status;
    result.message = std::move(message);
    result.elapsed = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start);
    return result;
  };
  const DepthIntrinsics& k = frame.intrinsics;
  if (frame.depth_m.empty() || frame.depth_m.type() != CV_32FC1 || !(k.fx_px > 0.0) || !(k.fy_px > 0.0)) {
    return finish(LocalizeStatus::kBadDepth, "depth image empty, not CV_32FC1, or intrinsics without a focal length");
  }
  const DepthGrid grid(frame, kGridCells, impl_->options.min_height_world_m);
  if (grid.finite_pixels() == 0) {
    return finish(LocalizeStatus::kBadDepth, "depth image has no finite depth");
  }
  const std::vector<Surface> surfaces = grid.surfaces(impl_->options.min_supporting_points);
  if (surfaces.empty()) {
    return finish(LocalizeStatus::kNoVisibleSurface,
                  "no connected surface of at least " + std::to_string(impl_->options.min_supporting_points) +
                      " points above the support (" + std::to_string(grid.valid_cells()) + " points in all)");
  }
  const Eigen::Isometry3d camera_world = frame.pose_world_camera.inverse();
  std::vector<Fit> fits;
  if (prior_world_object) {
    const Eigen::Isometry3d start_pose = camera_world * *prior_world_object;
    // Refined on what lies within the part's box near the prior (as far as it may be off), judged on
    // what lies within it at the pose found: not on a connected surface, which may hold more than the
    // part (the rope it hangs from, the part it stands on) or less (a face cut off by a hole).
    const Surface region = impl_->cropped(grid, surfaces, start_pose, kPriorOffM);
    if (static_cast<int>(region.cells.size()) >= impl_->options.min_supporting_points) {
      const SurfaceIndex nearest(grid, region);
      const Eigen::Isometry3d pose = impl_->finish(grid, nearest, start_pose);
      const Surface judged = impl_->cropped(grid, {region}, pose, kJudgedMarginM);
      // Refused, it is what a search is judged against, and reported if nothing better is found.
      fits.push_back(impl_->evaluate(grid, judged.cells, pose));
    } else if (!impl_->options.search_when_prior_fails) {
      return finish(LocalizeStatus::kNotFound, "only " + std::to_string(region.cells.size()) +
                                                   " points of the image within the part's box near its last pose");
    }
  }
  const bool prior_fits = !fits.empty() && impl_->acceptable(fits.front());
  const auto below_support = [&](const Fit& fit) {
    const Eigen::Isometry3d world_object = frame.pose_world_camera * fit.pose_camera_object;
    double lowest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < impl_->dense.points_m.size(); i += 10) {
      lowest = std::min(lowest, (world_object * impl_->dense.points_m[i]).z());
    }
    return std::max(0.0, *impl_->options.min_height_world_m - lowest);
  };
  if (!prior_fits && (!prior_world_object || impl_->options.search_when_prior_fails)) {
    impl_->find_model_faces();
    int tried = 0;
    for (const Surface& surface : surfaces) {
      // A surface wider than the part is not the part alone (the support, or parts touching).
      if (tried >= kSurfacesTried || surface.radius_m > 2.0 * impl_->radius_m) {
        continue;
      }
      // A fit scores at most its surface's points: one that could neither win nor tie is not searched.
      const bool outscored = std::any_of(fits.begin(), fits.end(), [&](const Fit& fit) {
        return impl_->acceptable(fit) && 0.97 * fit.score > static_cast<double>(surface.cells.size());
      });
      if (outscored) {
        break;
      }
      ++tried;
      impl_->search(grid, surface, fits);
      for (Fit& fit : fits) {
        fit.below_support_m = fit.searched && impl_->options.min_height_world_m ? below_support(fit) : 0.0;
      }
    }
    if (tried == 0 && fits.empty()) {
      return finish(LocalizeStatus::kNotFound, "every connected surface in the image is wider than the part (" +
                                                   std::to_string(surfaces.front().radius_m) + " m from its centre)");
    }
  }
  if (fits.empty()) {
    return finish(LocalizeStatus::kNotFound, "no pose hypothesis for the part in the depth image");
  }
  // Acceptable fits first, then by score: a refused one is reported only when none passes.
  std::sort(fits.begin(), fits.end(), [this](const Fit& a, const Fit& b) {
    const bool a_ok = impl_->acceptable(a);
    const bool b_ok = impl_->acceptable(b);
    return a_ok != b_ok ? a_ok : a.score > b.score;
  });
  const Fit& best = fits.front();
  result.pose_world_object = impl_->canonical(frame.pose_world_camera * best.pose_camera_object, prior_world_object);
  result.rms_m = best.rms_m;
  result.inlier_ratio = best.inlier_ratio;
  result.supporting_points = best.inliers;
  result.model_support = best.model_support;
  if (best.inliers < impl_->options.min_supporting_points) {
    return finish(LocalizeStatus::kNotFound, "best pose has " + std::to_string(best.inliers) +
                                                 " supporting points; at least " +
                                                 std::to_string(impl_->options.min_supporting_points) + " needed");
  }
  if (!impl_->acceptable(best)) {
    return finish(LocalizeStatus::kLowFit, "best pose fits with rms " + std::to_string(best.rms_m * 1000.0) +
                                               " mm, inlier ratio " + std::to_string(best.inlier_ratio) +
                                               ", model support " + std::to_string(best.model_support) +
                                               ", worst face direction " + std::to_string(best.worst_direction_ratio));
  }
  for (std::size_t i = 1; i < fits.size(); ++i) {
    const Fit& other = fits[i];
    if (impl_->acceptable(other) && other.score >= 0.97 * best.score &&
        !impl_->equivalent(best.pose_camera_object, other.pose_camera_object)) {
      return finish(LocalizeStatus::kAmbiguous, "two poses that are not symmetric equivalents fit equally well (" +
                                                    std::to_string(best.inliers) + " and " +
                                                    std::to_string(other.inliers) + " points)");
    }
  }
  return finish(LocalizeStatus::kFound, "");
}

}  // namespace rigger::perception
