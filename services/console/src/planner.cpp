#include "planner.hpp"
#include "placement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "rigger/base/bounded_json.hpp"

// The task controller's validator: the only place the console includes it (the library moves to
// common/recipe; this include follows it).
#include "rigger/recipe/conditions.hpp"
#include "rigger/recipe/live_library.hpp"
#include "rigger/recipe/recipe_validator.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

bool is_point(const json& p) {
  return p.is_array() && p.size() == 3 && p[0].is_number() && p[1].is_number() && p[2].is_number();
}

/// "object:<entity>" from body["model"]; returns the entity. `what` says what the entity must have.
std::string object_model(const json& body, std::string& model, const char* what) {
  const auto it = body.find("model");
  if (it == body.end() || !it->is_string())
    throw PlannerError{"/model", "expected the model as \"object:<entity id>\", e.g. \"object:target\""};
  model = it->get<std::string>();
  const std::string prefix = "object:";
  if (model.compare(0, prefix.size(), prefix) != 0 || model.size() == prefix.size() || model.size() > 200)
    throw PlannerError{"/model", std::string("expected \"object:<entity id>\" (") + what + "), not \"" +
                                     model.substr(0, 200) + "\""};
  return model.substr(prefix.size());
}

bool is_reference(const json& v) {
  return (v.is_number_integer() && v.get<long long>() >= 0) || (v.is_object() && v.contains("kind") && v.contains("index"));
}

}  // namespace

std::string imported_model_sha256(const json& body) {
  const std::string model = body.value("model", json()).is_string() ? body["model"].get<std::string>() : "";
  if (model.rfind("sha256:", 0) != 0 || model.size() != 7 + 64)
    throw PlannerError{"/model", "expected \"sha256:<hex>\", the imported file's model"};
  return model.substr(7);
}

void SkillCatalog::update(const std::string& executor_id, bool alive, const std::string& library_json) {
  std::lock_guard lock(mutex_);
  if (!alive) {
    libraries_.erase(executor_id);
    return;
  }
  libraries_[executor_id] = recipe::parse_announced_library(library_json);
}

skill::SkillLibrary SkillCatalog::merged(std::vector<std::string>* problems) const {
  // Exactly what the task controller validates against (common/recipe).
  std::vector<recipe::AnnouncedLibrary> announced;
  for (const auto& [id, doc] : libraries_) announced.push_back({id, &doc});
  return recipe::live_library(announced, problems);
}

skill::SkillLibrary SkillCatalog::library() const {
  std::lock_guard lock(mutex_);
  return merged(nullptr);
}

json SkillCatalog::to_json() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> problems;
  const skill::SkillLibrary library = merged(&problems);
  json executors = json::object();
  for (const auto& [id, doc] : libraries_) {
    json names = json::array();
    if (doc.is_object() && doc.contains("skills") && doc["skills"].is_array())
      for (const auto& s : doc["skills"])
        if (s.is_object() && s.contains("name") && s["name"].is_string()) names.push_back(s["name"]);
    executors[id] = names;
  }
  json skills = library.to_json().value("skills", json::array());
  return {{"skills", skills}, {"executors", executors}, {"problems", problems}};
}

std::string canonical_json(const json& document) {
  // nlohmann::json keeps object keys sorted: dump() is already in a stable key order.
  return document.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

json validate_recipe(const skill::SkillLibrary& library, std::string_view text) {
  const recipe::RecipeValidator validator(library);
  const recipe::ValidationResult result = validator.validate_text(text);
  json errors = json::array();
  for (const auto& e : result.errors) errors.push_back({{"pointer", e.pointer}, {"message", e.message}});
  json out = {{"ok", result.ok()}, {"errors", errors}};
  // The canonical text of whatever parses (with the validator's own bounds), valid or not: the page
  // exports it either way and says whether it validated.
  rigger::JsonLimits limits;
  limits.max_bytes = validator.options().limits.max_bytes;
  limits.max_depth = validator.options().limits.max_depth;
  const auto parsed = rigger::parse_json_bounded(text, limits);
  if (parsed.ok()) out["canonical"] = canonical_json(parsed.value);
  return out;
}

ScrewRequest parse_screw_request(const json& body) {
  ScrewRequest r;
  r.entity = object_model(body, r.model, "a cell object whose screw holes the world model knows");
  const auto holes = body.find("holes");
  if (holes == body.end() || !holes->is_array() || holes->empty() || holes->size() > 32)
    throw PlannerError{"/holes", "expected 1 to 32 picked holes (hole indices or face references)"};
  for (std::size_t i = 0; i < holes->size(); ++i) {
    const json& h = (*holes)[i];
    if (!is_reference(h))
      throw PlannerError{"/holes/" + std::to_string(i),
                         "expected a hole index (integer ≥ 0) or a face reference {\"model_sha256\", \"kind\", \"index\", \"signature\"}"};
  }
  r.holes = *holes;
  return r;
}

json screws_with_features(const ScrewRequest& request, const std::string& model_sha256, const json& cad_result,
                          const json& world_entity, double tolerance_m) {
  const json empty = json::array();
  const json* features = &empty;
  if (world_entity.contains("features") && world_entity["features"].is_object() &&
      world_entity["features"].contains("screw_holes") && world_entity["features"]["screw_holes"].is_array())
    features = &world_entity["features"]["screw_holes"];
  const auto screws = cad_result.find("screws");
  if (screws == cad_result.end() || !screws->is_array())
    throw PlannerError{"", "the CAD service's answer has no screw list"};
  json out = json::array();
  for (std::size_t i = 0; i < screws->size(); ++i) {
    const json& s = (*screws)[i];
    const json position = s.contains("pose") && s["pose"].is_object() ? s["pose"].value("position_m", json()) : json();
    if (!is_point(position)) throw PlannerError{"/holes/" + std::to_string(i), "the CAD service gave this hole no entry point"};
    std::string best_id;
    double best = std::numeric_limits<double>::infinity();
    const json* match = nullptr;
    for (const auto& f : *features) {
      if (!f.is_object() || !f.contains("id") || !f["id"].is_string()) continue;
      const json p = f.contains("pose") && f["pose"].is_object() ? f["pose"].value("position_m", json()) : f.value("position_m", json());
      if (!is_point(p)) continue;
      const double d = std::hypot(p[0].get<double>() - position[0].get<double>(), p[1].get<double>() - position[1].get<double>(),
                                  p[2].get<double>() - position[2].get<double>());
      if (d < best) {
        best = d;
        best_id = f["id"].get<std::string>();
        match = &f;
      }
    }
    if (match == nullptr || best > tolerance_m) {
      char where[160];
      std::snprintf(where, sizeof where, "[%.4f, %.4f, %.4f] m", position[0].get<double>(), position[1].get<double>(),
                    position[2].get<double>());
      throw PlannerError{"/holes/" + std::to_string(i),
                         "hole " + s.value("hole", json(-1)).dump() + " of model " + request.model + " (entry at " + where +
                             ") is not a screw hole the world model knows on " + request.entity +
                             (match == nullptr ? std::string(" (it has none)")
                                               : " (nearest: " + best_id + " at " + std::to_string(best * 1000.0).substr(0, 6) + " mm)")};
    }
    json screw = s;
    screw["feature"] = request.entity + "/" + best_id;
    screw["screw_type"] = match->value("screw_type", std::string());
    screw["torque_nm"] = match->value("torque_nm", 0.0);
    out.push_back(std::move(screw));
  }
  return {{"model", request.model}, {"model_sha256", model_sha256}, {"entity", request.entity}, {"screws", out}};
}

FrameRequest parse_frame_request(const json& body) {
  FrameRequest r;
  r.entity = object_model(body, r.model, "a cell object with a STEP model");
  const auto rule = body.find("rule");
  if (rule == body.end() || !rule->is_string())
    throw PlannerError{"/rule", "expected the frame rule: \"edges\" (a point and two perpendicular edges), \"face\" or \"hole\""};
  const std::string name = *rule;
  const auto point = [&] {
    const auto p = body.find("point_m");
    if (p == body.end() || !is_point(*p))
      throw PlannerError{"/point_m", "expected the picked point as [x, y, z] in metres, in the model's frame"};
    return *p;
  };
  const auto reference = [&](const char* key, const json& v, const std::string& pointer) {
    if (!is_reference(v))
      throw PlannerError{pointer, std::string("expected the ") + key +
                                      " as an index (integer ≥ 0) or a reference {\"model_sha256\", \"kind\", \"index\", \"signature\"}"};
    return v;
  };
  if (name == "edges") {
    const auto edges = body.find("edges");
    if (edges == body.end() || !edges->is_array() || edges->size() != 2)
      throw PlannerError{"/edges", "expected two picked edges: x along the first, y along the second"};
    r.args = {{"rule", name}, {"point_m", point()},
              {"edges", {reference("edge", (*edges)[0], "/edges/0"), reference("edge", (*edges)[1], "/edges/1")}}};
  } else if (name == "face") {
    const auto face = body.find("face");
    if (face == body.end()) throw PlannerError{"/face", "expected the picked face"};
    r.args = {{"rule", name}, {"face", reference("face", *face, "/face")}, {"point_m", point()}};
  } else if (name == "hole") {
    const auto hole = body.find("hole");
    if (hole == body.end() || !hole->is_number_integer() || hole->get<long long>() < 0)
      throw PlannerError{"/hole", "expected the hole's index in the model's features (integer ≥ 0)"};
    r.args = {{"rule", name}, {"hole", *hole}};
  } else {
    throw PlannerError{"/rule", "unknown frame rule \"" + name.substr(0, 40) + "\": expected \"edges\", \"face\" or \"hole\""};
  }
  return r;
}

json pose_from_cad_frame(const json& cad_result, const std::string& entity) {
  json pose = position_rpy(frame_from_cad(cad_result));
  pose["frame"] = entity;
  return pose;
}

}  // namespace rigger::console
