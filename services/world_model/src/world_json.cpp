#include "world_json.hpp"

#include <cmath>
#include <stdexcept>

namespace rigger::world {
namespace {

using nlohmann::json;

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

json vector_json(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json named_poses_json(const std::vector<NamedPose>& poses) {
  json result = json::array();
  for (const auto& named : poses) result.push_back({{"id", named.id}, {"pose", pose_to_config_json(named.pose_entity_feature)}});
  return result;
}

double finite_number(const json& value, const char* what) {
  if (!value.is_number()) throw std::invalid_argument(std::string(what) + ": expected a number");
  const double number = value.get<double>();
  if (!std::isfinite(number)) throw std::invalid_argument(std::string(what) + ": expected a finite number");
  return number;
}

}  // namespace

json pose_to_config_json(const Eigen::Isometry3d& pose) {
  // eulerAngles(2, 1, 0) returns (yaw, pitch, roll) for R = Rz(yaw) Ry(pitch) Rx(roll).
  const Eigen::Vector3d ypr = pose.linear().eulerAngles(2, 1, 0);
  return {{"position_m", vector_json(pose.translation())},
          {"rpy_deg", json::array({ypr[2] * kRadToDeg, ypr[1] * kRadToDeg, ypr[0] * kRadToDeg})}};
}

json pose_to_json(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  return {{"position_m", vector_json(pose.translation())}, {"quaternion_xyzw", json::array({q.x(), q.y(), q.z(), q.w()})}};
}

Eigen::Isometry3d pose_from_json(const json& value) {
  if (!value.is_object()) throw std::invalid_argument("pose: expected an object");
  const auto position = value.find("position_m");
  const auto quaternion = value.find("quaternion_xyzw");
  if (position == value.end() || !position->is_array() || position->size() != 3) {
    throw std::invalid_argument("pose/position_m: expected an array of 3 numbers");
  }
  if (quaternion == value.end() || !quaternion->is_array() || quaternion->size() != 4) {
    throw std::invalid_argument("pose/quaternion_xyzw: expected an array of 4 numbers");
  }
  const Eigen::Vector3d t(finite_number((*position)[0], "pose/position_m/0"), finite_number((*position)[1], "pose/position_m/1"),
                          finite_number((*position)[2], "pose/position_m/2"));
  Eigen::Quaterniond q(finite_number((*quaternion)[3], "pose/quaternion_xyzw/3"),
                       finite_number((*quaternion)[0], "pose/quaternion_xyzw/0"),
                       finite_number((*quaternion)[1], "pose/quaternion_xyzw/1"),
                       finite_number((*quaternion)[2], "pose/quaternion_xyzw/2"));
  if (std::abs(q.norm() - 1.0) > 1e-6) throw std::invalid_argument("pose/quaternion_xyzw: expected a unit quaternion");
  q.normalize();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = t;
  return pose;
}

json features_to_json(const CadFeatures& features) {
  json result = json::object();
  if (features.rope_attachment) result["rope_attachment"] = pose_to_config_json(*features.rope_attachment);
  if (!features.grasp_frames.empty()) result["grasp_frames"] = named_poses_json(features.grasp_frames);
  if (!features.approach_waypoints.empty()) result["approach_waypoints"] = named_poses_json(features.approach_waypoints);
  if (!features.screw_holes.empty()) {
    json holes = json::array();
    for (const auto& hole : features.screw_holes) {
      holes.push_back({{"id", hole.id},
                       {"pose", pose_to_config_json(hole.pose_entity_hole)},
                       {"screw_type", hole.screw_type},
                       {"torque_nm", hole.torque_nm}});
    }
    result["screw_holes"] = holes;
  }
  if (features.markers) {
    json items = json::array();
    for (const auto& marker : features.markers->items) {
      items.push_back({{"id", marker.id}, {"size_m", marker.size_m}, {"pose", pose_to_config_json(marker.pose_entity_marker)}});
    }
    result["markers"] = {{"dictionary", features.markers->dictionary}, {"items", items}};
  }
  if (features.insertion) {
    result["insertion"] = {{"target", features.insertion->target},
                           {"pose_in_target", pose_to_config_json(features.insertion->pose_target_entity)}};
  }
  return result;
}

json entity_to_json(const Entity& entity) {
  json result = {{"id", entity.id},
                 {"kind", std::string(to_string(entity.kind))},
                 {"parent", entity.parent},
                 {"localized", entity.localized},
                 {"stale", entity.stale},
                 {"stamp_ns", to_unix_ns(entity.stamp)},
                 {"source", entity.source},
                 {"features", features_to_json(entity.features)},
                 {"attributes", entity.attributes}};
  if (entity.pose) {
    result["pose"] = pose_to_json(entity.pose->pose_parent_entity);
    result["pose_stamp_ns"] = to_unix_ns(entity.pose->stamp);
    result["pose_source"] = entity.pose->source;
    if (entity.pose->covariance) {
      json covariance = json::array();
      for (int row = 0; row < 6; ++row) {
        for (int col = 0; col < 6; ++col) covariance.push_back((*entity.pose->covariance)(row, col));
      }
      result["covariance"] = covariance;
    }
    if (entity.pose->quality) result["quality"] = *entity.pose->quality;
  }
  if (entity.model) {
    result["model"] = {{"shape", entity.model->shape}, {"size_m", vector_json(entity.model->size_m)},
                       {"frame", entity.model->frame}, {"static", entity.model->is_static}};
    if (entity.model->mass_kg) result["model"]["mass_kg"] = *entity.model->mass_kg;
  }
  if (entity.camera) {
    const CameraIntrinsics& camera = *entity.camera;
    result["camera"] = {{"width", camera.width_px}, {"height", camera.height_px}, {"fx", camera.fx_px},
                        {"fy", camera.fy_px},          {"cx", camera.cx_px},            {"cy", camera.cy_px},
                        {"distortion", camera.distortion}, {"rate_hz", camera.rate_hz},
                        {"noise_stddev", camera.noise_stddev}, {"optical_frame", camera.optical_frame}};
  }
  return result;
}

std::int64_t to_unix_ns(Stamp stamp) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(stamp.time_since_epoch()).count();
}

Stamp from_unix_ns(std::int64_t ns) {
  return Stamp(std::chrono::duration_cast<Stamp::duration>(std::chrono::nanoseconds(ns)));
}

}  // namespace rigger::world
