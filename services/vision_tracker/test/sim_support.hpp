#pragma once
/// @file
/// Test and benchmark support: the tracker's configuration for the simulated cell, and frames of
/// it rendered by the simulated camera with their ground truth.

#include "rigger/sim/camera_renderer.hpp"
#include "tracker_config.hpp"

#include <random>
#include <string>
#include <vector>

namespace rigger::vision::testing {

/// The repository's cell configuration.
std::string cell_json_path();
/// deploy/cell/simulated_cell.json, the cell the deployment runs.
std::string deployed_cell_json_path();

/// The camera "camera" and the object layouts of a cell file as a tracker configuration.
TrackerConfig tracker_config_from_file(const std::string& cell_json);

/// Render settings for the tests: distinct albedos, the given noise.
sim::RenderSettings render_settings(double noise_stddev, std::uint64_t seed = 7);

/// The scene's configured poses of all its objects.
std::vector<sim::ObjectPose> scenario_poses(const sim::CameraScene& scene);

/// The scenario's poses with the load raised 0.3 m: in the scenario's own poses the hanging load
/// hides the target's markers from the camera.
std::vector<sim::ObjectPose> both_visible_poses(const sim::CameraScene& scene);

/// Random poses around the scenario's in which every marker of every object is fully visible and
/// 1 to 2.1 m from the camera: the load (hanging, so mostly yawing) within +-0.45 m sideways,
/// -0.15..+0.1 m in depth and 0..+0.4 m in height (it must clear the line of sight to the target's
/// markers) and +-20 deg yaw, +-4 deg roll and pitch; the target within +-0.1 m and +-10 deg yaw.
std::vector<sim::ObjectPose> random_visible_poses(const sim::CameraRenderer& renderer, const sim::CameraScene& scene,
                                                  std::mt19937& rng);

/// Translation error (m) and rotation error (rad) of an estimate against the truth.
double translation_error_m(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
double rotation_error_rad(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

/// The q-quantile (0..1) of values (by nearest rank).
double quantile(std::vector<double> values, double q);

}  // namespace rigger::vision::testing
