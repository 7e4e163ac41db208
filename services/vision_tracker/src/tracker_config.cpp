#include "tracker_config.hpp"

#include <opencv2/aruco/dictionary.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "rigger/cell_config/calibration_board.hpp"

namespace rigger::vision {
namespace {

void require(bool ok, const std::string& field, const std::string& expected) {
  if (!ok) {
    throw TrackerConfigError("tracker configuration: " + field + ": expected " + expected);
  }
}

bool is_rotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         std::abs(r.determinant() - 1.0) < 1e-6;
}

}  // namespace

void validate(const TrackerConfig& config) {
  const CameraIntrinsics& camera = config.camera;
  require(camera.width_px > 0 && camera.width_px <= 16384, "camera.width_px", "1..16384");
  require(camera.height_px > 0 && camera.height_px <= 16384, "camera.height_px", "1..16384");
  require(std::isfinite(camera.fx_px) && camera.fx_px > 0.0, "camera.fx_px", "a positive focal length");
  require(std::isfinite(camera.fy_px) && camera.fy_px > 0.0, "camera.fy_px", "a positive focal length");
  require(std::isfinite(camera.cx_px) && std::isfinite(camera.cy_px), "camera.cx_px/cy_px", "finite values");
  const std::size_t n = camera.distortion.size();
  require(n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14, "camera.distortion",
          "none, or 4, 5, 8, 12 or 14 coefficients (OpenCV's order), not " + std::to_string(n));
  for (std::size_t k = 0; k < n; ++k) {
    require(std::isfinite(camera.distortion[k]), "camera.distortion[" + std::to_string(k) + "]", "a finite value");
  }
  require(config.pose_world_camera.translation().allFinite() && is_rotation(config.pose_world_camera.linear()),
          "pose_world_camera", "a finite rigid transform");

  require(config.detector.dictionary >= cv::aruco::DICT_4X4_50 &&
              config.detector.dictionary <= cv::aruco::DICT_APRILTAG_36h11,
          "detector.dictionary", "a cv::aruco predefined dictionary id");
  const int dictionary_size = cv::aruco::getPredefinedDictionary(config.detector.dictionary)->bytesList.rows;
  require(config.detector.min_marker_side_px >= 4.0, "detector.min_marker_side_px", ">= 4");
  require(config.detector.min_side_canonical_px >= 8, "detector.min_side_canonical_px", ">= 8");
  require(config.detector.roi_margin_fraction >= 0.0 && config.detector.roi_margin_px >= 0, "detector.roi_margin_*",
          ">= 0");
  require(config.detector.reacquire_every_n_frames >= 1, "detector.reacquire_every_n_frames", ">= 1");
  require(config.detector.region_threshold_window_px == 0 ||
              (config.detector.region_threshold_window_px >= 3 && config.detector.region_threshold_window_px % 2 == 1),
          "detector.region_threshold_window_px", "0 or an odd number >= 3");

  const EstimatorSettings& est = config.estimator;
  require(est.max_reprojection_rms_px > 0.0, "estimator.max_reprojection_rms_px", "> 0");
  require(est.quality_reprojection_scale_px > 0.0, "estimator.quality_reprojection_scale_px", "> 0");
  require(est.good_viewing_angle_deg >= 0.0 && est.good_viewing_angle_deg < est.grazing_viewing_angle_deg &&
              est.grazing_viewing_angle_deg <= 90.0,
          "estimator.good_viewing_angle_deg/grazing_viewing_angle_deg", "0 <= good < grazing <= 90");
  require(est.min_quality >= 0.0 && est.min_quality < 1.0, "estimator.min_quality", "a value in [0, 1)");
  require(est.min_pixel_sigma_px > 0.0, "estimator.min_pixel_sigma_px", "> 0");

  const FilterSettings& filter = config.filter;
  require(filter.position_gain > 0.0 && filter.position_gain <= 1.0, "filter.position_gain", "a value in (0, 1]");
  require(filter.velocity_gain >= 0.0 && filter.velocity_gain < 4.0 - 2.0 * filter.position_gain,
          "filter.velocity_gain", "a value in [0, 4 - 2 * position_gain) (stable alpha-beta filter)");
  require(filter.max_prediction.count() > 0, "filter.max_prediction", "> 0");
  require(filter.reset_distance_m > 0.0 && filter.reset_angle_deg > 0.0, "filter.reset_*", "> 0");
  require(config.lost_after.count() >= 0, "lost_after", ">= 0");

  require(!config.objects.empty(), "objects", "at least one object layout");
  std::map<int, std::string> owner;
  for (std::size_t i = 0; i < config.objects.size(); ++i) {
    const ObjectLayout& object = config.objects[i];
    const std::string where = "objects[" + std::to_string(i) + "]";
    require(!object.object_id.empty(), where + ".object_id", "a non-empty id");
    require(!object.markers.empty(), where + ".markers", "at least one marker for '" + object.object_id + "'");
    for (std::size_t j = 0; j < config.objects.size(); ++j) {
      require(j == i || config.objects[j].object_id != object.object_id, where + ".object_id",
              "a unique id ('" + object.object_id + "' appears twice)");
    }
    for (std::size_t m = 0; m < object.markers.size(); ++m) {
      const MarkerPlacement& marker = object.markers[m];
      const std::string field = where + ".markers[" + std::to_string(m) + "]";
      require(marker.id >= 0 && marker.id < dictionary_size, field + ".id",
              "an id in [0, " + std::to_string(dictionary_size) + ")");
      require(std::isfinite(marker.size_m) && marker.size_m > 0.0, field + ".size_m", "a positive size");
      require(marker.pose_object_marker.translation().allFinite() && is_rotation(marker.pose_object_marker.linear()),
              field + ".pose_object_marker", "a finite rigid transform");
      const auto [it, inserted] = owner.emplace(marker.id, object.object_id);
      require(inserted, field + ".id",
              "a marker id used once (" + std::to_string(marker.id) + " is also on '" + it->second + "')");
    }
  }
}

TrackerConfig tracker_config_from_cell(const cell::CellFile& file, const std::string& camera_id) {
  const cell::CellEntity& camera = file.require(camera_id, "the camera the tracker looks through");
  if (!camera.camera) {
    file.fail(camera.pointer + "/camera", "the intrinsics of camera \"" + camera_id + "\"", "nothing (missing key)");
  }
  TrackerConfig config;
  config.camera = *camera.camera;
  config.pose_world_camera = file.pose_root_entity(camera_id);

  // Every marker layout (the objects', and the calibration boards on robots' tools under their own ids) in
  // one dictionary.
  std::string dictionary;
  const auto add = [&](const std::string& id, const cell::MarkerLayout& layout, const std::string& pointer) {
    if (!dictionary.empty() && layout.dictionary != dictionary) {
      file.fail(pointer + "/dictionary", "the dictionary of every other layout (" + dictionary + ")",
                "\"" + layout.dictionary + "\"");
    }
    dictionary = layout.dictionary;
    ObjectLayout object{id, {}};
    for (const cell::Marker& marker : layout.items) {
      object.markers.push_back({marker.id, marker.size_m, marker.pose_entity_marker});
    }
    config.objects.push_back(std::move(object));
  };
  for (const cell::CellEntity& entity : file.entities) {
    if (entity.features.markers) add(entity.id, *entity.features.markers, entity.pointer + "/features/markers");
  }
  for (const cell::CellEntity& entity : file.entities) {
    if (entity.calibration_board) {
      add(cell::calibration_board_id(entity.id), entity.calibration_board->markers,
          entity.pointer + "/calibration_board/markers");
    }
  }
  if (!dictionary.empty()) config.detector.dictionary = cell::marker_dictionary(dictionary)->opencv_id;
  return config;
}

bool same_view(const TrackerConfig& a, const TrackerConfig& b) {
  const CameraIntrinsics& ca = a.camera;
  const CameraIntrinsics& cb = b.camera;
  if (ca.width_px != cb.width_px || ca.height_px != cb.height_px || ca.fx_px != cb.fx_px || ca.fy_px != cb.fy_px ||
      ca.cx_px != cb.cx_px || ca.cy_px != cb.cy_px || ca.distortion != cb.distortion ||
      a.pose_world_camera.matrix() != b.pose_world_camera.matrix() || a.objects.size() != b.objects.size())
    return false;
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    const ObjectLayout& oa = a.objects[i];
    const ObjectLayout& ob = b.objects[i];
    if (oa.object_id != ob.object_id || oa.markers.size() != ob.markers.size()) return false;
    for (std::size_t m = 0; m < oa.markers.size(); ++m) {
      const MarkerPlacement& ma = oa.markers[m];
      const MarkerPlacement& mb = ob.markers[m];
      if (ma.id != mb.id || ma.size_m != mb.size_m || ma.pose_object_marker.matrix() != mb.pose_object_marker.matrix())
        return false;
    }
  }
  return true;
}

}  // namespace rigger::vision
