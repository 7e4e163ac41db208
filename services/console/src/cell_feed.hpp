#pragma once
/// @file
/// Where things are in the cell, for the pages' 3D cell: every object's pose in the world frame (from the
/// world model's entities, each posed in its parent's frame), the robot's tool position and the crane's
/// hook position (each in the frame of the device entity its state names), turned into the changes a
/// page needs. The console asks for the changes at most `rate` times a second, so no entity reaches a
/// page faster; a pose that moved less than 0.5 mm and 0.1° since it was last sent is not sent again.
///
/// A change (and the whole picture, which is a change from nothing) is one JSON object:
///
///   {"t": <s since the epoch>,
///    "objects": {"<id>": {"position_m": [x, y, z], "quaternion_xyzw": [x, y, z, w]}, ...},
///    "tool": [x, y, z], "hook": [x, y, z]}        world frame, metres; keys absent when unchanged
///
/// An object whose pose is not known (yet), or whose chain of parents does not reach the world frame,
/// is left out until it is known. Thread safety: none (the console's loop owns it).
#include <map>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace rigger::console {

/// Applies a change to a picture (both as above): objects by id, tool and hook replaced; "t" becomes
/// the change's.
void merge_cell(nlohmann::json& picture, const nlohmann::json& change);

class CellFeed {
 public:
  /// The world model's entity `id` (kind "object", "device" or "frame"), posed in `parent`'s frame
  /// (nullopt: not known).
  void entity(const std::string& id, const std::string& kind, const std::string& parent,
              const std::optional<Eigen::Isometry3d>& pose_parent_entity);
  /// The robot's tool position in the frame of entity `frame` (its base: the robot entity).
  void tool(const std::string& frame, const Eigen::Vector3d& position_frame_tool_m);
  /// The crane's hook position in the frame of entity `frame` (the crane entity: x bridge, y trolley,
  /// z hook height).
  void hook(const std::string& frame, const Eigen::Vector3d& position_frame_hook_m);

  /// What changed since the last call (stamped `now_s`), or nullopt when nothing did.
  std::optional<nlohmann::json> take_changes(double now_s);
  /// Whether anything came since the last take_changes() (it may still be too small to send).
  bool dirty() const { return dirty_; }

 private:
  struct Frame {
    std::string kind, parent;
    std::optional<Eigen::Isometry3d> pose_parent;
  };
  struct Point {
    std::string frame;
    Eigen::Vector3d position_frame = Eigen::Vector3d::Zero();
    bool known = false;
  };
  std::optional<Eigen::Isometry3d> world_pose(const std::string& id) const;
  std::optional<Eigen::Vector3d> world_point(const Point& p) const;

  std::map<std::string, Frame> frames_;
  Point tool_, hook_;
  std::map<std::string, Eigen::Isometry3d> sent_objects_;
  std::optional<Eigen::Vector3d> sent_tool_, sent_hook_;
  bool dirty_ = false;
};

}  // namespace rigger::console
