#include "rigger/cell_config/cell_types.hpp"

#include <map>

namespace rigger::cell {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

std::string_view to_string(EntityKind kind) {
  switch (kind) {
    case EntityKind::kObject:
      return "object";
    case EntityKind::kDevice:
      return "device";
    case EntityKind::kFrame:
      return "frame";
  }
  return "unknown";
}

std::string stale_model_problem(const ObjectModel& model, std::string_view actual_sha256) {
  if (model.step_sha256.empty() || model.step_sha256 == actual_sha256) return {};
  return "CAD_STALE_MODEL: " + model.step + " has sha256 " + std::string(actual_sha256) + ", the cell file pins " +
         model.step_sha256 + " (model.sha256)";
}

std::optional<EntityKind> entity_kind_from_string(std::string_view text) {
  if (text == "object") return EntityKind::kObject;
  if (text == "device") return EntityKind::kDevice;
  if (text == "frame") return EntityKind::kFrame;
  return std::nullopt;
}

std::optional<MarkerDictionary> marker_dictionary(std::string_view name) {
  // The values of cv::aruco::PREDEFINED_DICTIONARY_NAME (stable since OpenCV 3), kept here so that
  // readers of the cell file need no OpenCV; the camera's tests check them against OpenCV.
  static const std::map<std::string_view, MarkerDictionary> kDictionaries = {{"DICT_4X4_50", {0, 50}},
                                                                             {"DICT_4X4_100", {1, 100}},
                                                                             {"DICT_4X4_250", {2, 250}},
                                                                             {"DICT_4X4_1000", {3, 1000}},
                                                                             {"DICT_5X5_50", {4, 50}},
                                                                             {"DICT_5X5_100", {5, 100}},
                                                                             {"DICT_5X5_250", {6, 250}},
                                                                             {"DICT_5X5_1000", {7, 1000}},
                                                                             {"DICT_6X6_50", {8, 50}},
                                                                             {"DICT_6X6_100", {9, 100}},
                                                                             {"DICT_6X6_250", {10, 250}},
                                                                             {"DICT_6X6_1000", {11, 1000}},
                                                                             {"DICT_7X7_50", {12, 50}},
                                                                             {"DICT_7X7_100", {13, 100}},
                                                                             {"DICT_7X7_250", {14, 250}},
                                                                             {"DICT_7X7_1000", {15, 1000}},
                                                                             {"DICT_ARUCO_ORIGINAL", {16, 1024}},
                                                                             {"DICT_APRILTAG_16h5", {17, 30}},
                                                                             {"DICT_APRILTAG_25h9", {18, 35}},
                                                                             {"DICT_APRILTAG_36h10", {19, 2320}},
                                                                             {"DICT_APRILTAG_36h11", {20, 587}}};
  const auto it = kDictionaries.find(name);
  if (it == kDictionaries.end()) return std::nullopt;
  return it->second;
}

std::optional<CadRuleKind> cad_rule_from_string(std::string_view text) {
  if (text == "face") return CadRuleKind::kFace;
  if (text == "hole") return CadRuleKind::kHole;
  if (text == "mate_faces") return CadRuleKind::kMateFaces;
  return std::nullopt;
}

const CadRule* CadFeatures::pending_cad() const {
  const auto pending = [](const std::optional<CadRule>& rule) { return rule && !rule->derived; };
  for (const auto& list : {&grasp_frames, &approach_waypoints}) {
    for (const NamedPose& named : *list) {
      if (pending(named.cad)) return &*named.cad;
    }
  }
  for (const ScrewHole& hole : screw_holes) {
    if (pending(hole.cad)) return &*hole.cad;
  }
  if (insertion && pending(insertion->cad)) return &*insertion->cad;
  return nullptr;
}

bool CadFeatures::empty() const {
  return !rope_attachment && grasp_frames.empty() && approach_waypoints.empty() && screw_holes.empty() && !markers &&
         !insertion;
}

std::optional<Eigen::Isometry3d> CadFeatures::find_pose(std::string_view feature_id) const {
  if (feature_id == "rope_attachment") return rope_attachment;
  for (const auto& grasp : grasp_frames) {
    if (grasp.id == feature_id) return grasp.pose_entity_feature;
  }
  for (const auto& waypoint : approach_waypoints) {
    if (waypoint.id == feature_id) return waypoint.pose_entity_feature;
  }
  for (const auto& hole : screw_holes) {
    if (hole.id == feature_id) return hole.pose_entity_hole;
  }
  return std::nullopt;
}

Eigen::Matrix3d CameraIntrinsics::camera_matrix() const {
  Eigen::Matrix3d k;
  k << fx_px, 0.0, cx_px, 0.0, fy_px, cy_px, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Matrix3d rotation_from_rpy_deg(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d rpy_rad = rpy_deg * (kPi / 180.0);
  return (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Isometry3d pose_from_position_rpy_deg(const Eigen::Vector3d& position_m, const Eigen::Vector3d& rpy_deg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation_from_rpy_deg(rpy_deg);
  pose.translation() = position_m;
  return pose;
}

}  // namespace rigger::cell
