#include "model_localizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "rigger/cad/tessellation.hpp"

namespace rigger::vision {
namespace {

std::string fit_text(const perception::LocalizeResult& r) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "rms %.1f mm, %.0f %% of the surface on the model, %.0f %% of the model seen, %d points",
                r.rms_m * 1e3, r.inlier_ratio * 100.0, r.model_support * 100.0, r.supporting_points);
  return buf;
}

}  // namespace

double unseen_share(const perception::Mesh& mesh, const Eigen::Isometry3d& pose_world_object,
                    const perception::DepthFrame& frame) {
  constexpr double kSpacingM = 0.004;
  constexpr double kSeenM = 0.005;
  constexpr double kMinFacing = 0.34;  // cos 70°
  const Eigen::Isometry3d pose_camera_object = frame.pose_world_camera.inverse() * pose_world_object;
  const perception::DepthIntrinsics& k = frame.intrinsics;
  // Outward normals whichever way the mesh is wound: the sign of its volume says which way that is.
  double volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    volume += mesh.vertices_m[static_cast<std::size_t>(t.x())].dot(
        mesh.vertices_m[static_cast<std::size_t>(t.y())].cross(mesh.vertices_m[static_cast<std::size_t>(t.z())]));
  }
  const double outward = volume < 0.0 ? -1.0 : 1.0;
  std::mt19937 rng(1);  // the same samples every time: the measure of a pose is repeatable
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double seen = 0.0, unseen = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = pose_camera_object * mesh.vertices_m[static_cast<std::size_t>(t.x())];
    const Eigen::Vector3d b = pose_camera_object * mesh.vertices_m[static_cast<std::size_t>(t.y())];
    const Eigen::Vector3d c = pose_camera_object * mesh.vertices_m[static_cast<std::size_t>(t.z())];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area = 0.5 * cross.norm();
    if (!(area > 0.0)) continue;
    const Eigen::Vector3d n = outward * cross / (2.0 * area);
    const int samples = std::max(1, static_cast<int>(std::lround(area / (kSpacingM * kSpacingM))));
    for (int i = 0; i < samples; ++i) {
      double u = unit(rng), v = unit(rng);
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      const Eigen::Vector3d p = a + u * (b - a) + v * (c - a);
      const double facing = -n.dot(p.normalized());
      // Faces away (hidden by the part itself), or seen so obliquely that a sensor leaves holes there anyway.
      if (facing < kMinFacing) continue;
      if (p.z() <= 0.0) continue;
      const int px = static_cast<int>(std::lround(k.fx_px * p.x() / p.z() + k.cx_px));
      const int py = static_cast<int>(std::lround(k.fy_px * p.y() / p.z() + k.cy_px));
      if (px < 0 || py < 0 || px >= frame.depth_m.cols || py >= frame.depth_m.rows) continue;  // out of view
      const float z = frame.depth_m.at<float>(py, px);
      if (!std::isfinite(z) || z <= 0.0F) {
        unseen += facing;
      } else if (z > p.z() - kSeenM) {
        seen += facing;  // seen, or seen through (the fit checks judge that)
      }
      // else hidden by something nearer (another object)
    }
  }
  return seen + unseen > 0.0 ? unseen / (seen + unseen) : 1.0;
}

std::string status_code(perception::LocalizeStatus status) {
  switch (status) {
    case perception::LocalizeStatus::kFound: return "FOUND";
    case perception::LocalizeStatus::kNotFound: return "NOT_FOUND";
    case perception::LocalizeStatus::kAmbiguous: return "AMBIGUOUS";
    case perception::LocalizeStatus::kLowFit: return "LOW_FIT";
    case perception::LocalizeStatus::kBadDepth: return "BAD_DEPTH";
    case perception::LocalizeStatus::kNoVisibleSurface: return "NO_VISIBLE_SURFACE";
    case perception::LocalizeStatus::kBadMesh: return "NO_MODEL";
  }
  return "NOT_FOUND";
}

void ModelLocalizer::set_cell(const cell::CellFile& file, const std::filesystem::path& model_dir) {
  cell_ = file;
  model_dir_ = model_dir;
  meshes_.clear();
}

bool ModelLocalizer::has_model(const std::string& object_id) const {
  const cell::CellEntity* entity = cell_.find(object_id);
  return entity != nullptr && entity->kind == cell::EntityKind::kObject && entity->model && !entity->model->step.empty();
}

const perception::Mesh* ModelLocalizer::mesh(const std::string& object_id, std::string& problem) {
  if (const auto known = meshes_.find(object_id); known != meshes_.end()) return &known->second;
  if (!has_model(object_id)) {
    problem = "'" + object_id + "' is no object of the cell with a STEP model (model.step)";
    return nullptr;
  }
  const cell::ObjectModel& model = *cell_.find(object_id)->model;
  const std::filesystem::path path = model_dir_ / model.step;
  try {
    const cad::Model read = cad::read_step_file(path);
    if (const std::string stale = cell::stale_model_problem(model, read.sha256()); !stale.empty()) {
      problem = path.string() + ": " + stale;
      return nullptr;
    }
    cad::TriangleMesh triangles = cad::triangle_mesh(read);
    perception::Mesh mesh{std::move(triangles.vertices_m), std::move(triangles.triangles)};
    perception::Localizer check(mesh);  // throws for a mesh it cannot use: better now than per frame
    return &meshes_.emplace(object_id, std::move(mesh)).first->second;
  } catch (const std::exception& e) {
    problem = path.string() + ": " + e.what();
    return nullptr;
  }
}

ModelLocalization ModelLocalizer::localize(const std::string& object_id, const perception::DepthFrame& frame,
                                           const std::optional<Eigen::Isometry3d>& prior_world_object) {
  std::string problem;
  const perception::Mesh* part = mesh(object_id, problem);
  if (part == nullptr) {
    ModelLocalization out;
    out.status = "NO_MODEL";
    out.detail = problem;
    return out;
  }
  return localize_mesh(*part, frame, prior_world_object);
}

ModelLocalization localize_mesh(const perception::Mesh& mesh, const perception::DepthFrame& frame,
                                const std::optional<Eigen::Isometry3d>& prior_world_object, bool tracking) {
  ModelLocalization out;
  const perception::Mesh* part = &mesh;
  perception::LocalizeOptions options;
  options.search_when_prior_fails = !tracking;
  // A load held by the robot shows a few per cent of its camera-facing points seen through (the arm and the
  // magnet behind its silhouette): its correct poses score 0.87 to 1 (kTrackedModelSupport).
  if (tracking) options.min_model_support = ModelLocalizer::kTrackedModelSupport;
  if (prior_world_object) {
    double lowest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& v : part->vertices_m) lowest = std::min(lowest, (*prior_world_object * v).z());
    options.min_height_world_m = lowest + ModelLocalizer::kSupportMarginM;
  }
  // Construction only samples the mesh (milliseconds); the support height is per request.
  perception::Localizer localizer(*part, options);
  out.result = localizer.localize(frame, prior_world_object);
  out.status = status_code(out.result.status);
  if (out.found()) {
    const double unseen = unseen_share(*part, out.result.pose_world_object, frame);
    if (unseen > ModelLocalizer::kMaxUnseenShare) {
      out.status = "LOW_FIT";
      char buf[160];
      std::snprintf(buf, sizeof buf, "%.0f %% of the surface facing the camera lands where the image has no depth (at most %.0f %%)",
                    unseen * 100.0, ModelLocalizer::kMaxUnseenShare * 100.0);
      out.detail = buf;
      out.detail += " (best: " + fit_text(out.result) + ")";
      return out;
    }
    out.pose_world_object = out.result.pose_world_object;
    out.quality = std::clamp(out.result.inlier_ratio, 0.0, 1.0);
    out.detail = fit_text(out.result);
  } else {
    out.detail = out.result.message;
    if (out.result.status == perception::LocalizeStatus::kLowFit ||
        out.result.status == perception::LocalizeStatus::kAmbiguous) {
      out.detail += " (best: " + fit_text(out.result) + ")";
    }
  }
  return out;
}

}  // namespace rigger::vision
