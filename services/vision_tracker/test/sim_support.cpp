#include "sim_support.hpp"


#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rigger::vision::testing {

// The unit tests use a frozen copy of the cell (they assert numbers derived for that geometry, such as
// the hanging load hiding the target); the accuracy test uses the deployed cell.
std::string cell_json_path() {
  return std::string(RIGGER_SOURCE_DIR) + "/services/cell_sim/camera/test/data/camera_test_cell.json";
}
std::string deployed_cell_json_path() { return std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json"; }

TrackerConfig tracker_config_from_file(const std::string& cell_json) {
  return tracker_config_from_cell(cell::load_cell_file(cell_json), "camera");
}

sim::RenderSettings render_settings(double noise_stddev, std::uint64_t seed) {
  sim::RenderSettings settings;
  settings.noise_stddev = noise_stddev;
  settings.albedo = {{"load", 0.62}, {"target", 0.38}};
  settings.seed = seed;
  return settings;
}

std::vector<sim::ObjectPose> scenario_poses(const sim::CameraScene& scene) {
  std::vector<sim::ObjectPose> poses;
  for (const sim::BoxObject& object : scene.objects) {
    poses.push_back({object.id, object.pose_world_object});
  }
  return poses;
}

std::vector<sim::ObjectPose> both_visible_poses(const sim::CameraScene& scene) {
  std::vector<sim::ObjectPose> poses = scenario_poses(scene);
  for (sim::ObjectPose& pose : poses) {
    if (pose.object_id == "load") {
      pose.pose_world_object.translation().z() += 0.3;
    }
  }
  return poses;
}

std::vector<sim::ObjectPose> random_visible_poses(const sim::CameraRenderer& renderer, const sim::CameraScene& scene,
                                                  std::mt19937& rng) {
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const auto deg = [](double d) { return d * M_PI / 180.0; };
  for (int attempt = 0; attempt < 1000; ++attempt) {
    std::vector<sim::ObjectPose> poses = scenario_poses(scene);
    for (sim::ObjectPose& pose : poses) {
      // The crane scenario's objects move; the small part of Pick and Place and its table stay where the
      // cell file puts them (the camera sees the part's marker from farther away).
      if (pose.object_id != "load" && pose.object_id != "target") continue;
      const bool load = pose.object_id == "load";
      Eigen::Vector3d offset;
      Eigen::Matrix3d turn;
      if (load) {
        offset = {uniform(-0.45, 0.45), uniform(-0.15, 0.1), uniform(0.0, 0.4)};
        turn = (Eigen::AngleAxisd(deg(uniform(-20, 20)), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(deg(uniform(-4, 4)), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(deg(uniform(-4, 4)), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
      } else {
        offset = {uniform(-0.1, 0.1), uniform(-0.1, 0.1), 0.0};
        turn = Eigen::AngleAxisd(deg(uniform(-10, 10)), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      }
      pose.pose_world_object.translation() += offset;
      pose.pose_world_object.linear() = turn * pose.pose_world_object.linear();
    }
    const std::vector<sim::MarkerView> views = renderer.marker_views(scene.pose_world_camera, poses);
    const bool all_visible = std::all_of(views.begin(), views.end(), [](const sim::MarkerView& v) {
      const bool moved = v.object_id == "load" || v.object_id == "target";
      return v.visible_fraction == 1.0 && (!moved || (v.distance_m >= 1.0 && v.distance_m <= 2.1));
    });
    if (all_visible) {
      return poses;
    }
  }
  throw std::runtime_error("random_visible_poses: no pose with every marker visible in 1000 attempts");
}

double translation_error_m(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return (estimate.translation() - truth.translation()).norm();
}

double rotation_error_rad(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return Eigen::AngleAxisd(estimate.linear().transpose() * truth.linear()).angle();
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) {
    return std::nan("");
  }
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

}  // namespace rigger::vision::testing
