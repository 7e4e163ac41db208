#include "rigger/skill_sdk/pose_param.hpp"

#include <cmath>
#include <stdexcept>

namespace rigger::skill_sdk {

namespace {
Eigen::Vector3d vec3(const nlohmann::json& a, const char* what) {
  if (!a.is_array() || a.size() != 3) throw std::invalid_argument(std::string(what) + ": expected 3 numbers");
  return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}
}  // namespace

PoseParam pose_from_param(const nlohmann::json& value, const std::string& default_frame) {
  if (!value.is_object() || !value.contains("position_m")) throw std::invalid_argument("pose: expected an object with position_m");
  PoseParam out;
  out.frame = value.value("frame", default_frame);
  out.pose.translation() = vec3(value.at("position_m"), "position_m");
  if (value.contains("quaternion_xyzw")) {
    const auto& q = value.at("quaternion_xyzw");
    if (!q.is_array() || q.size() != 4) throw std::invalid_argument("quaternion_xyzw: expected 4 numbers");
    Eigen::Quaterniond quat(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>());
    if (quat.norm() < 1e-9) throw std::invalid_argument("quaternion_xyzw: zero quaternion");
    out.pose.linear() = quat.normalized().toRotationMatrix();
  } else if (value.contains("rpy_deg")) {
    const Eigen::Vector3d rpy = vec3(value.at("rpy_deg"), "rpy_deg") * (M_PI / 180.0);
    out.pose.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                            .toRotationMatrix();
  }
  return out;
}

}  // namespace rigger::skill_sdk
