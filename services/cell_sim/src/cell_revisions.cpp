#include "cell_revisions.hpp"

#include <algorithm>
#include <array>

namespace rigger::cell_sim {
namespace {

using nlohmann::json;

// Entity keys the physics and the camera never read: a revision changing only these needs nothing.
constexpr std::array<const char*, 4> kIgnoredKeys = {"localized", "comment", "description", "attributes"};

std::string ids_of(const json& list) {
  std::string text;
  for (const json& id : list) text += (text.empty() ? "" : ", ") + id.get<std::string>();
  return text;
}

RevisionPlan refuse(std::string why) {
  return {{}, std::move(why)};
}

}  // namespace

RevisionPlan plan_revision(const json& changes, const cell::CellFile& next) {
  try {
    const json none = json::array();
    const json& added = changes.contains("added") ? changes.at("added") : none;
    const json& removed = changes.contains("removed") ? changes.at("removed") : none;
    if (!added.empty() || !removed.empty())
      return refuse("it adds or removes " + ids_of(added) + (added.empty() || removed.empty() ? "" : ", ") +
                    ids_of(removed) + ": cell_sim builds its model at start; restart it on the new cell");
    for (const json& changed : changes.value("changed", none)) {
      for (const json& key : changed.at("keys")) {
        const std::string k = key.get<std::string>();
        if (std::find(kIgnoredKeys.begin(), kIgnoredKeys.end(), k) != kIgnoredKeys.end()) continue;
        return refuse("it changes " + k + " of " + changed.at("id").get<std::string>() +
                      ": cell_sim builds its model at start; restart it on the new cell");
      }
    }
    RevisionPlan plan;
    for (const json& moved : changes.value("moved", none)) {
      const std::string id = moved.at("id").get<std::string>();
      const cell::CellEntity* entity = next.find(id);
      if (entity == nullptr) return refuse("it moves " + id + ", which it does not hold");
      if (entity->kind != cell::EntityKind::kObject)
        return refuse("it moves the device or frame " + id + ": cell_sim places devices at start; restart it");
      plan.moves.push_back({id, next.pose_root_entity(id)});
    }
    return plan;
  } catch (const std::exception& e) {
    return refuse(std::string("its changes are not in the expected form: ") + e.what());
  }
}

}  // namespace rigger::cell_sim
