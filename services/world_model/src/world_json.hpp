#pragma once
/// @file
/// JSON forms of world-model values: poses, CAD features and entity states, as used by persistence and
/// by the wire's `*_json` fields; plus small helpers for error messages (JSON pointers, short
/// renderings of offending values).

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "rigger/cell_config/json_text.hpp"
#include "world_types.hpp"

namespace rigger::world {

// Pointers, value renderings and the id form of the cell file's reader (rigger_cell_config).
using cell::describe_json;
using cell::is_valid_identifier;
using cell::join_pointer;

/// `{"position_m": [x, y, z], "rpy_deg": [roll, pitch, yaw]}`, the cell configuration's pose form
/// (R = Rz(yaw) Ry(pitch) Rx(roll)).
nlohmann::json pose_to_config_json(const Eigen::Isometry3d& pose);

/// `{"position_m": [x, y, z], "quaternion_xyzw": [x, y, z, w]}`, the exact form used for persistence.
nlohmann::json pose_to_json(const Eigen::Isometry3d& pose);
/// Inverse of pose_to_json.
/// @throws std::invalid_argument when the shape is wrong, a number is not finite or the quaternion is
///   not unit within 1e-6.
Eigen::Isometry3d pose_from_json(const nlohmann::json& value);

/// CAD features in the cell configuration's `features` format (poses as position_m + rpy_deg); an
/// empty object when there are none. This is what a features query returns.
nlohmann::json features_to_json(const CadFeatures& features);

/// An entity's full description for replies and UIs: id, kind, parent, pose (position_m and
/// quaternion_xyzw), stamps (`stamp_ns`, `pose_stamp_ns`: ns since the Unix epoch), source,
/// localized, stale, covariance (36 numbers, row-major), quality, features, model, camera, attributes.
nlohmann::json entity_to_json(const Entity& entity);

/// Nanoseconds since the Unix epoch.
std::int64_t to_unix_ns(Stamp stamp);
/// The stamp `ns` nanoseconds after the Unix epoch.
Stamp from_unix_ns(std::int64_t ns);

}  // namespace rigger::world
