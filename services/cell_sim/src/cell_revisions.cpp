#include "cell_revisions.hpp"

#include <algorithm>
#include <array>

namespace rigger::cell_sim {
namespace {

using nlohmann::json;

// Entity keys the physics and the camera never read: a revision changing only these needs nothing.
constexpr std::array<const char*, 4> kIgnoredKeys = {"localized", "comment", "description", "attributes"};

constexpr const char* kRestart = ": cell_sim places devices at start; restart it on the new cell";

RevisionPlan refuse(std::string why) {
  RevisionPlan plan;
  plan.refusal = std::move(why);
  return plan;
}

bool is_object(const cell::CellEntity* entity) {
  return entity != nullptr && entity->kind == cell::EntityKind::kObject;
}

bool is_static(const cell::CellEntity* entity) {
  return is_object(entity) && entity->model && entity->model->is_static;
}

// The crane's load: the object with a rope attachment (cell_geometry checks that there is one).
const cell::CellEntity* load_of(const cell::CellFile& file) {
  for (const cell::CellEntity& entity : file.entities) {
    if (is_object(&entity) && entity.features.rope_attachment) return &entity;
  }
  return nullptr;
}

void note(std::string& reason, const std::string& what, const std::string& id) {
  reason += (reason.empty() ? "" : "; ") + what + " " + id;
}

// The arm of the physics (cell_geometry's robot) by its entity id.
constexpr const char* kPhysicsRobot = "robot";

// What a revision does to the board on the arm's tool: a geom of the gripper, built with the model.
std::string board_change(const cell::CellFile& running, const cell::CellFile& next) {
  const cell::CellEntity* before = running.find(kPhysicsRobot);
  const cell::CellEntity* after = next.find(kPhysicsRobot);
  const bool had = before != nullptr && before->calibration_board.has_value();
  const bool has = after != nullptr && after->calibration_board.has_value();
  if (!had) return "mounts the calibration board on";
  return has ? "changes the calibration board of" : "unmounts the calibration board from";
}

}  // namespace

RevisionPlan plan_revision(const json& changes, const cell::CellFile& running, const cell::CellFile& next) {
  try {
    const json none = json::array();
    RevisionPlan plan;
    const cell::CellEntity* load = load_of(running);
    const std::string load_id = load != nullptr ? load->id : std::string();
    const cell::CellEntity* next_load = load_of(next);
    if (load != nullptr && (next_load == nullptr || next_load->id != load_id))
      return refuse("it takes the crane's load " + load_id + " off the rope" +
                    (next_load != nullptr ? " for " + next_load->id : std::string()) +
                    ": cell_sim hangs the load at start; restart it on the new cell");
    for (const json& id_json : changes.value("added", none)) {
      const std::string id = id_json.get<std::string>();
      if (!is_object(next.find(id))) return refuse("it adds the device or frame " + id + kRestart);
      note(plan.rebuild_reason, "adds", id);
    }
    for (const json& id_json : changes.value("removed", none)) {
      const std::string id = id_json.get<std::string>();
      if (!is_object(running.find(id))) return refuse("it removes the device or frame " + id + kRestart);
      note(plan.rebuild_reason, "removes", id);
    }
    for (const json& changed : changes.value("changed", none)) {
      const std::string id = changed.at("id").get<std::string>();
      for (const json& key : changed.at("keys")) {
        const std::string k = key.get<std::string>();
        if (std::find(kIgnoredKeys.begin(), kIgnoredKeys.end(), k) != kIgnoredKeys.end()) continue;
        // A board mounted or unmounted is a geom of the gripper: the model is built anew with or without it.
        if (k == "calibration_board" && id == kPhysicsRobot) {
          note(plan.rebuild_reason, board_change(running, next), id);
          continue;
        }
        if (!is_object(next.find(id))) return refuse("it changes " + k + " of the device or frame " + id + kRestart);
        if (id == load_id && k == "model")
          return refuse("it reshapes the crane's load " + id +
                        ", which hangs from the rope: cell_sim hangs the load at start; restart it on the new cell");
        if (id == load_id && k == "features" &&
            !next_load->features.rope_attachment->isApprox(*load->features.rope_attachment, 1e-9))
          return refuse("it moves the rope attachment of the crane's load " + id +
                        ": cell_sim hangs the load at start; restart it on the new cell");
        note(plan.rebuild_reason, "changes " + k + " of", id);
      }
    }
    for (const json& moved : changes.value("moved", none)) {
      const std::string id = moved.at("id").get<std::string>();
      const cell::CellEntity* entity = next.find(id);
      if (entity == nullptr) return refuse("it moves " + id + ", which it does not hold");
      // A camera drawn elsewhere: its drawing is corrected, the camera (its true pose) is not moved.
      if (entity->kind == cell::EntityKind::kDevice && entity->camera && running.find(id) != nullptr &&
          running.find(id)->camera) {
        plan.cameras_redrawn.push_back(id);
        continue;
      }
      if (entity->kind != cell::EntityKind::kObject)
        return refuse("it moves the device or frame " + id + ": cell_sim places devices at start; restart it");
      // A static object is where the model puts it: built anew; a free one is put there after.
      if (is_static(entity)) {
        note(plan.rebuild_reason, "moves the static", id);
      } else {
        plan.moves.push_back({id, next.pose_root_entity(id)});
      }
    }
    plan.rebuild = !plan.rebuild_reason.empty();
    return plan;
  } catch (const std::exception& e) {
    return refuse(std::string("its changes are not in the expected form: ") + e.what());
  }
}

}  // namespace rigger::cell_sim
