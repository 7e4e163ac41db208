#pragma once
/// @file
/// The admittance_control service's configuration file (JSON; its keys, declared once in
/// control_settings(), are listed in docs/config-reference.md#admittance_control, the tuning is in
/// docs/control.md): the node's timeouts and cell file, loop rates and the parameters of the robot law,
/// the crane law and the visual servo. Every key is optional (defaults as in the structs); unknown keys
/// are refused. Also the reader of the insertion offset from an object's CAD features. Setup-time only:
/// everything here throws rigger::ConfigError naming the file, the JSON pointer and what was expected.

#include <filesystem>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "crane_admittance.hpp"
#include "rigger/admittance_control/settings.hpp"
#include "rigger/base/config.hpp"
#include "robot_admittance.hpp"
#include "visual_servo.hpp"

namespace rigger::cell {
struct CellFile;
}  // namespace rigger::cell

namespace rigger::control {

/// Everything the admittance_control service is configured with.
struct ControlConfig {
  // The node's keys (top level of the file).
  double twist_timeout_s = 0.05;  ///< timeout_s of each cmd_twist
  double crane_timeout_s = 0.2;   ///< timeout_s of each crane cmd_velocity
  /// The cell file, found by the rule of rigger/base/install.hpp; absent: the robot base is the world frame.
  std::optional<std::filesystem::path> cell_file;
  std::string robot_id = "robot";      ///< the robot's entity in the cell file and cmd_twist's frame id
  double crane_state_timeout_s = 0.5;  ///< an older rigger/crane/state in ROBOT_AND_CRANE is a CRANE_FAULT
  double commander_grace_s = 2.0;      ///< a command's source must be seen alive within it
  std::string rope_object = "load";    ///< the tracked object whose rope attachment gives the rope offset
  double rope_offset_max_age_s = 0.2;  ///< an older tracker pose of rope_object gives no rope offset
  double robot_rate_hz = 500.0;        ///< robot law loop rate, Hz
  double crane_rate_hz = 50.0;         ///< crane law loop rate, Hz
  RobotAdmittanceConfig robot;
  CraneAdmittanceConfig crane;
  /// The servo's gains and limits; its insertion offset comes with each servo request from the world
  /// model (insertion_offset_from_features()), so the configured one stays the identity.
  VisualServoConfig visual_servo;
};

/// Reads the configuration from its root object (the node's keys and the "robot", "crane",
/// "visual_servo" sections) with control_settings(), then the rules that relate several keys (the laws'
/// find_problem(), a loop period within max_time_step_s), and checks every key (config.finish()).
/// @throws rigger::ConfigError on a wrong type, a value out of range, a broken rule or an unknown key.
ControlConfig load_control_config(const Config& config);

/// Reads the configuration file at `path`. @throws rigger::ConfigError.
ControlConfig load_control_config_file(const std::string& path);

/// A pose in the cell configuration's form {"position_m": [x, y, z], "rpy_deg": [roll, pitch, yaw]}
/// with R = Rz(yaw) Ry(pitch) Rx(roll). `source` and `pointer` name the value in errors.
/// @throws rigger::ConfigError when a key is missing or not three finite numbers, or a key is unknown.
Eigen::Isometry3d pose_from_config_json(const nlohmann::json& value, const std::string& source,
                                        const std::string& pointer);

/// The insertion offset (the load's pose in the target's frame) from an object's CAD features in
/// the cell configuration's form: `features.insertion.pose_in_target`.
/// @throws rigger::ConfigError naming `source` and the JSON pointer (below "/insertion") when absent
///   or malformed.
Eigen::Isometry3d insertion_offset_from_features(const nlohmann::json& features, const std::string& source);

/// The pose in the world of the entity `entity_id` of a cell file (deploy/cell/*.json: an
/// "entities" array of {id, parent, pose}), e.g. the robot's base. The entity's parent must be
/// "world" (nested parents are not resolved here).
/// @throws rigger::ConfigError naming `path` and the JSON pointer when the file cannot be read, the
///   entity is missing, has another parent or a malformed pose.
Eigen::Isometry3d entity_pose_from_cell_file(const std::string& path, const std::string& entity_id);

/// The same from a cell already read (e.g. a cell revision); errors name `source`.
Eigen::Isometry3d entity_pose_in_cell(const cell::CellFile& cell, const std::string& source,
                                      const std::string& entity_id);

/// Where the rope hooks into `object` (its rope_attachment feature, in its frame).
/// @throws rigger::ConfigError naming `source` when the object is missing or has no rope attachment.
Eigen::Isometry3d rope_attachment_in_cell(const cell::CellFile& cell, const std::string& source,
                                          const std::string& object);

}  // namespace rigger::control
