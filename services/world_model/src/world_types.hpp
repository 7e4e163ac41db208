#pragma once
/// @file
/// The world model's domain types: entities (objects, devices, frames), their poses in a parent frame,
/// their CAD features, camera intrinsics (the cell file's types, from rigger_cell_config) and free
/// attributes. Pure C++ (Eigen, nlohmann::json), no DDS.
///
/// Conventions used throughout `rigger::world`:
/// - Poses are `Eigen::Isometry3d` named `pose_<frame>_<entity>`: the pose of `entity` expressed in
///   `frame` (it maps points from the entity's frame into `frame`). Metres and radians.
/// - Stamps are wall-clock time since the Unix epoch (`std::chrono::system_clock`, nanosecond
///   resolution with libstdc++), the same type as `rigger::WallTime` and the wire's `geometry::Time`.
/// - A 6x6 covariance is over (x, y, z, rotation about x, y, z) in the parent frame, row-major on the
///   wire, as ROS 2's geometry_msgs/PoseWithCovariance (m², rad²).

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_types.hpp"

namespace rigger::world {

/// Wall-clock time since the Unix epoch; identical to `rigger::WallTime`.
using Stamp = std::chrono::system_clock::time_point;
/// Pose covariance over (x, y, z, rx, ry, rz), m² and rad².
using Covariance6d = Eigen::Matrix<double, 6, 6>;

// The cell file's types are the world model's (rigger_cell_config).
using cell::CadFeatures;
using cell::CameraIntrinsics;
using cell::EntityKind;
using cell::Insertion;
using cell::Marker;
using cell::MarkerLayout;
using cell::NamedPose;
using cell::ObjectModel;
using cell::ScrewHole;
using cell::entity_kind_from_string;
using cell::pose_from_position_rpy_deg;
using cell::rotation_from_rpy_deg;
using cell::to_string;

/// A pose estimate of an entity in its parent frame.
struct PoseEstimate {
  Eigen::Isometry3d pose_parent_entity = Eigen::Isometry3d::Identity();
  Stamp stamp{};          ///< when the pose was observed (or, for configuration poses, loaded)
  std::string source;     ///< who produced it: "config:<file>", a tracker id, a skill id
  std::optional<Covariance6d> covariance;  ///< when the producer gives one
  std::optional<double> quality;           ///< in [0, 1] when the producer gives one
};

/// One entity of the world. A root frame has an empty `parent` and no pose; every other entity has a
/// parent and, once known, a pose in it.
struct Entity {
  std::string id;
  EntityKind kind = EntityKind::kObject;
  std::string parent;                 ///< id of the parent frame/entity; empty for a root frame
  std::optional<PoseEstimate> pose;   ///< std::nullopt: pose not known yet (e.g. a tool not reported)
  bool localized = false;             ///< the pose is a current estimate usable for motion
  bool stale = false;                 ///< restored from persistence after a restart; never fresh
  Stamp stamp{};                      ///< stamp of the last accepted change (configuration: load time)
  std::string source;                 ///< who made the last accepted change
  CadFeatures features;
  std::optional<ObjectModel> model;
  std::optional<CameraIntrinsics> camera;
  nlohmann::json attributes = nlohmann::json::object();  ///< free attributes, always a JSON object
};

/// Entities by id (ordered, so listings and serialisations are deterministic).
using EntityMap = std::map<std::string, Entity, std::less<>>;

}  // namespace rigger::world
