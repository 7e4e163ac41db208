#include "rigger/cell_config/cell_diff.hpp"

#include <cmath>
#include <map>

namespace rigger::cell {
namespace {

using json = nlohmann::json;

constexpr double kMovedTranslationM = 1e-6;
constexpr double kMovedRotationRad = 1e-6;
constexpr double kPi = 3.14159265358979323846;

// The entity objects of a validated document by id.
std::map<std::string, const json*> entity_objects(const json& document) {
  std::map<std::string, const json*> out;
  const auto it = document.find("entities");
  if (it == document.end() || !it->is_array()) return out;
  for (const json& e : *it)
    if (e.is_object() && e.contains("id") && e["id"].is_string()) out.emplace(e["id"].get<std::string>(), &e);
  return out;
}

std::vector<std::string> changed_keys(const json& before, const json& after) {
  std::set<std::string> keys;
  for (const auto& [key, value] : before.items()) keys.insert(key);
  for (const auto& [key, value] : after.items()) keys.insert(key);
  std::vector<std::string> out;
  for (const std::string& key : keys) {
    if (key == "id" || key == "pose" || key == "parent" || key == "comment") continue;
    const auto b = before.find(key), a = after.find(key);
    if (b == before.end() || a == after.end() || *b != *a) out.push_back(key);
  }
  return out;
}

}  // namespace

json diff_cells(const CellFile& before, const json& before_doc, const CellFile& after, const json& after_doc) {
  json added = json::array(), removed = json::array(), moved = json::array(), changed = json::array();
  const auto before_objects = entity_objects(before_doc), after_objects = entity_objects(after_doc);
  for (const CellEntity& e : before.entities)
    if (after.find(e.id) == nullptr) removed.push_back(e.id);
  for (const CellEntity& e : after.entities) {
    const CellEntity* old = before.find(e.id);
    if (old == nullptr) {
      added.push_back(e.id);
      continue;
    }
    const Eigen::Isometry3d from = before.pose_root_entity(e.id), to = after.pose_root_entity(e.id);
    const double distance_m = (to.translation() - from.translation()).norm();
    const double angle_rad = Eigen::AngleAxisd(from.linear().transpose() * to.linear()).angle();
    if (old->parent != e.parent || distance_m > kMovedTranslationM || std::abs(angle_rad) > kMovedRotationRad) {
      moved.push_back({{"id", e.id},
                       {"distance_m", distance_m},
                       {"angle_deg", std::abs(angle_rad) * 180.0 / kPi},
                       {"parent_before", old->parent},
                       {"parent_after", e.parent}});
    }
    const auto b = before_objects.find(e.id), a = after_objects.find(e.id);
    if (b != before_objects.end() && a != after_objects.end()) {
      std::vector<std::string> keys = changed_keys(*b->second, *a->second);
      if (!keys.empty()) changed.push_back({{"id", e.id}, {"keys", keys}});
    }
  }
  return {{"added", added}, {"removed", removed}, {"moved", moved}, {"changed", changed}};
}

bool no_changes(const json& changes) {
  for (const char* key : {"added", "removed", "moved", "changed"})
    if (changes.contains(key) && !changes[key].empty()) return false;
  return true;
}

std::set<std::string> touched_entities(const json& changes) {
  std::set<std::string> ids;
  for (const json& id : changes.value("removed", json::array())) ids.insert(id.get<std::string>());
  for (const char* key : {"moved", "changed"})
    for (const json& item : changes.value(key, json::array())) ids.insert(item.at("id").get<std::string>());
  return ids;
}

std::set<std::string> moved_entities(const json& changes) {
  std::set<std::string> ids;
  for (const json& item : changes.value("moved", json::array())) ids.insert(item.at("id").get<std::string>());
  return ids;
}

std::string summarize_changes(const json& changes) {
  std::string text;
  for (const char* key : {"added", "removed", "moved", "changed"}) {
    const std::size_t n = changes.value(key, json::array()).size();
    if (n > 0) text += (text.empty() ? "" : ", ") + std::to_string(n) + " " + key;
  }
  return text.empty() ? "no change" : text;
}

}  // namespace rigger::cell
