#pragma once
/// @file
/// Reading a checked `pose` parameter ({"position_m": [x,y,z], "rpy_deg": [r,p,y] | "quaternion_xyzw":
/// [x,y,z,w], "frame"?}) into an Eigen pose. R = Rz(yaw) Ry(pitch) Rx(roll), as the cell file.

#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace rigger::skill_sdk {

struct PoseParam {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::string frame;  ///< the param's "frame", or `default_frame`
};

/// @throws std::invalid_argument when the value is not a pose (params are checked before, so this
/// names a programming error) or its quaternion is zero.
PoseParam pose_from_param(const nlohmann::json& value, const std::string& default_frame);

}  // namespace rigger::skill_sdk
