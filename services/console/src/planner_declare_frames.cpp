#include "planner_declare_frames.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "placement.hpp"
#include "rigger/cell_config/cell_types.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

double size_of(const DeclareRequest& r) {
  const json size = r.picks.value("size_m", json());
  if (!size.is_number() || !(size.get<double>() >= 0.01) || size.get<double>() > 1.0)
    throw PlannerError{"/size_m", "expected the marker's side in metres, at least 0.01 and at most 1"};
  return size.get<double>();
}

json* entity_of(json& doc, const std::string& id) {
  if (doc.contains("entities") && doc["entities"].is_array())
    for (json& e : doc["entities"])
      if (e.is_object() && e.value("id", "") == id) return &e;
  return nullptr;
}

}  // namespace

std::string rope_holder(const json& cell, const std::string& except) {
  for (const json& e : cell.value("entities", json::array()))
    if (e.is_object() && e.value("id", "") != except && e.contains("features") && e["features"].is_object() &&
        e["features"].contains("rope_attachment"))
      return e.value("id", "");
  return "";
}

json frame_args(const DeclareRequest& r) {
  const json& p = r.picks;
  if (r.kind == "rope_attachment" && p.contains("above_centre_of_mass")) {
    if (p["above_centre_of_mass"] != true)
      throw PlannerError{"/above_centre_of_mass", "expected true (a sling above the part's centre of mass), or leave it out"};
    return {{"rule", "above_centre_of_mass"}};
  }
  if (r.kind == "rope_attachment" && p.contains("hole")) {
    if (!p["hole"].is_number_integer() || p["hole"].get<long long>() < 0)
      throw PlannerError{"/hole", "expected the picked hole's index (integer ≥ 0)"};
    return {{"rule", "hole"}, {"hole", p["hole"]}};
  }
  const json point = p.value("point_m", json());
  if (!p.contains("face") || !p["face"].is_number_integer() || !point.is_array() || point.size() != 3 ||
      !point[0].is_number() || !point[1].is_number() || !point[2].is_number())
    throw PlannerError{r.kind == "marker" ? "/face" : "/hole",
                       r.kind == "marker" ? "expected the picked face and the point on it (\"face\", \"point_m\")"
                                          : "expected a picked hole, or a face and the point on it"};
  return {{"rule", "face"}, {"face", p["face"]}, {"point_m", point}};
}

std::array<Eigen::Vector3d, 4> marker_corners(const DeclareRequest& r, const Eigen::Isometry3d& at) {
  const double h = size_of(r) / 2;
  std::array<Eigen::Vector3d, 4> corners;
  const double signs[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) corners[i] = at * Eigen::Vector3d(signs[i][0] * h, signs[i][1] * h, 0);
  return corners;
}

json declare_at_frame(const DeclareRequest& r, const json& cell, const Eigen::Isometry3d& at) {
  json doc = cell;
  json* entity = entity_of(doc, r.entity);
  if (entity == nullptr) throw PlannerError{"/model", "the running cell revision has no entity \"" + r.entity + "\""};
  json& features = (*entity)["features"];
  if (!features.is_object()) features = json::object();
  const json pose = position_rpy(at);
  if (r.kind == "rope_attachment") {
    if (entity->contains("model") && (*entity)["model"].is_object() && (*entity)["model"].value("static", false))
      throw PlannerError{"/model", "\"" + r.entity + "\" is fixed (static): the crane's rope hooks a loose part"};
    if (features.contains("rope_attachment"))
      throw PlannerError{"/kind", "\"" + r.entity + "\" has a rope attachment already: roll back its revision first"};
    features["rope_attachment"] = pose;
    // The crane carries one load: the rope moves here from the object it hooked (if any).
    std::string rope_from;
    for (json& e : doc["entities"]) {
      if (!e.is_object() || e.value("id", "") == r.entity || !e.contains("features") || !e["features"].is_object() ||
          !e["features"].contains("rope_attachment"))
        continue;
      e["features"].erase("rope_attachment");
      rope_from = e.value("id", "");
    }
    json out = {{"cell", std::move(doc)}, {"features", {r.entity + "/rope_attachment"}}, {"rule", json::array({pose})}};
    if (!rope_from.empty()) out["rope_from"] = rope_from;
    return out;
  }
  const std::string dictionary = r.picks.value("dictionary", json()).is_string() ? r.picks["dictionary"].get<std::string>() : "";
  const std::optional<cell::MarkerDictionary> known = cell::marker_dictionary(dictionary);
  if (!known) throw PlannerError{"/dictionary", "expected an ArUco dictionary such as \"DICT_4X4_50\", got \"" + dictionary.substr(0, 32) + "\""};
  const json id = r.picks.value("marker_id", json());
  if (!id.is_number_integer() || id.get<long long>() < 0 || id.get<long long>() >= known->size)
    throw PlannerError{"/marker_id", "expected a marker id of " + dictionary + ", 0 to " + std::to_string(known->size - 1)};
  for (const json& e : doc["entities"]) {
    const json markers = e.is_object() && e.contains("features") && e["features"].is_object()
                             ? e["features"].value("markers", json::object())
                             : json::object();
    for (const json& m : markers.value("items", json::array()))
      if (m.value("id", -1) == id.get<long long>())
        throw PlannerError{"/marker_id", "marker " + id.dump() + " is on \"" + e.value("id", "") + "\" already: the tracker tells objects apart by their ids"};
  }
  json& markers = features["markers"];
  if (!markers.is_object()) markers = {{"dictionary", dictionary}, {"items", json::array()}};
  if (markers.value("dictionary", "") != dictionary)
    throw PlannerError{"/dictionary", "the markers of \"" + r.entity + "\" are of " + markers.value("dictionary", "?") + ": one dictionary per object"};
  const json item = {{"id", id}, {"size_m", size_of(r)}, {"pose", pose}};
  markers["items"].push_back(item);
  return {{"cell", std::move(doc)}, {"features", {r.entity + "/marker " + id.dump()}}, {"rule", json::array({item})}};
}

std::string marker_view_note(const json& cell, const std::string& entity, int marker_id, const Eigen::Isometry3d& at) {
  constexpr double kGoodDeg = 60.0;  // vision_tracker's good_viewing_angle_deg (its default)
  const Eigen::Isometry3d marker = world_pose_of(cell, entity) * at;
  double nearest = 180.0;
  std::string seen_by;
  for (const json& e : cell.value("entities", json::array())) {
    if (!e.is_object() || !e.contains("camera")) continue;
    const Eigen::Vector3d to_camera = world_pose_of(cell, e.value("id", "")).translation() - marker.translation();
    if (to_camera.norm() < 1e-9) continue;
    const double angle = std::acos(std::clamp(to_camera.normalized().dot(marker.linear().col(2)), -1.0, 1.0)) * 180.0 / M_PI;
    if (angle < nearest) {
      nearest = angle;
      seen_by = e.value("id", "");
    }
  }
  if (seen_by.empty() || nearest <= kGoodDeg) return "";
  return "Camera " + seen_by + " sees marker " + std::to_string(marker_id) + " at " + std::to_string(std::lround(nearest)) +
         " degrees from its normal where " + entity + " stands now: the tracker weighs a marker down past " +
         std::to_string(std::lround(kGoodDeg)) + " degrees and not at all past 85, so a pose from it is poor or none " +
         "(a face that looks at the camera is better).";
}

}  // namespace rigger::console
