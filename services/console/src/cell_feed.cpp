#include "cell_feed.hpp"

#include <cmath>

namespace rigger::console {

using nlohmann::json;

namespace {

constexpr double kMoveM = 0.0005;
constexpr double kTurnRad = 0.1 * M_PI / 180.0;
constexpr int kMaxDepth = 32;  // a longer chain of parents is a loop

// Positions to 0.1 mm and quaternions to 1e-5 keep a change short.
double round_to(double v, double step) {
  return std::round(v / step) * step;
}

json position_json(const Eigen::Vector3d& p) {
  return json::array({round_to(p.x(), 1e-4), round_to(p.y(), 1e-4), round_to(p.z(), 1e-4)});
}

json pose_json(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  return {{"position_m", position_json(pose.translation())},
          {"quaternion_xyzw",
           json::array({round_to(q.x(), 1e-5), round_to(q.y(), 1e-5), round_to(q.z(), 1e-5), round_to(q.w(), 1e-5)})}};
}

bool moved(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  if ((a.translation() - b.translation()).norm() >= kMoveM) return true;
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() >= kTurnRad;
}

}  // namespace

void merge_cell(json& picture, const json& change) {
  if (!picture.is_object()) picture = json::object();
  for (const auto& [key, value] : change.items()) {
    if (key == "objects" && value.is_object()) {
      json& objects = picture["objects"];
      if (!objects.is_object()) objects = json::object();
      for (const auto& [id, pose] : value.items()) objects[id] = pose;
    } else {
      picture[key] = value;
    }
  }
}

void CellFeed::entity(const std::string& id, const std::string& kind, const std::string& parent,
                      const std::optional<Eigen::Isometry3d>& pose_parent_entity) {
  frames_[id] = {kind, parent, pose_parent_entity};
  dirty_ = true;
}

void CellFeed::tool(const std::string& frame, const Eigen::Vector3d& position_frame_tool_m) {
  tool_ = {frame, position_frame_tool_m, true};
  dirty_ = true;
}

void CellFeed::hook(const std::string& frame, const Eigen::Vector3d& position_frame_hook_m) {
  hook_ = {frame, position_frame_hook_m, true};
  dirty_ = true;
}

std::optional<Eigen::Isometry3d> CellFeed::world_pose(const std::string& id) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::string at = id;
  for (int depth = 0; depth < kMaxDepth; ++depth) {
    const auto it = frames_.find(at);
    // The root: the world frame (an entity without a parent, or a parent no entity names).
    if (it == frames_.end()) return depth == 0 ? std::nullopt : std::optional(pose);
    if (it->second.parent.empty()) return pose;
    if (!it->second.pose_parent) return std::nullopt;
    pose = *it->second.pose_parent * pose;
    at = it->second.parent;
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> CellFeed::world_point(const Point& p) const {
  if (!p.known) return std::nullopt;
  if (p.frame.empty()) return p.position_frame;
  const auto frame = world_pose(p.frame);
  if (!frame) return std::nullopt;
  return *frame * p.position_frame;
}

std::optional<json> CellFeed::take_changes(double now_s) {
  if (!dirty_) return std::nullopt;
  dirty_ = false;
  json change = {{"t", round_to(now_s, 1e-3)}};
  json objects = json::object();
  for (const auto& [id, frame] : frames_) {
    if (frame.kind != "object") continue;
    const auto pose = world_pose(id);
    if (!pose) continue;
    const auto sent = sent_objects_.find(id);
    if (sent != sent_objects_.end() && !moved(sent->second, *pose)) continue;
    sent_objects_[id] = *pose;
    objects[id] = pose_json(*pose);
  }
  if (!objects.empty()) change["objects"] = std::move(objects);
  const auto point = [&](const Point& p, std::optional<Eigen::Vector3d>& sent, const char* key) {
    const auto world = world_point(p);
    if (!world || (sent && (*world - *sent).norm() < kMoveM)) return;
    sent = *world;
    change[key] = position_json(*world);
  };
  point(tool_, sent_tool_, "tool");
  point(hook_, sent_hook_, "hook");
  if (change.size() == 1) return std::nullopt;
  return change;
}

}  // namespace rigger::console
