#include "planner.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "rigger/skill/bounded_json.hpp"

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

}  // namespace

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
  skill::JsonLimits limits;
  limits.max_bytes = validator.options().limits.max_bytes;
  limits.max_depth = validator.options().limits.max_depth;
  const auto parsed = skill::parse_json_bounded(text, limits);
  if (parsed.ok()) out["canonical"] = canonical_json(parsed.value);
  return out;
}

ScrewRequest parse_screw_request(const json& body) {
  ScrewRequest r;
  const auto model = body.find("model");
  if (model == body.end() || !model->is_string())
    throw PlannerError{"/model", "expected the model as \"object:<entity id>\", e.g. \"object:target\""};
  r.model = model->get<std::string>();
  const std::string prefix = "object:";
  if (r.model.compare(0, prefix.size(), prefix) != 0 || r.model.size() == prefix.size() || r.model.size() > 200)
    throw PlannerError{"/model", "expected \"object:<entity id>\" (a cell object whose screw holes the world model "
                                 "knows), not \"" + r.model.substr(0, 200) + "\""};
  r.entity = r.model.substr(prefix.size());
  const auto holes = body.find("holes");
  if (holes == body.end() || !holes->is_array() || holes->empty() || holes->size() > 32)
    throw PlannerError{"/holes", "expected 1 to 32 picked holes (hole indices or face references)"};
  for (std::size_t i = 0; i < holes->size(); ++i) {
    const json& h = (*holes)[i];
    if (!(h.is_number_integer() && h.get<long long>() >= 0) && !(h.is_object() && h.contains("kind") && h.contains("index")))
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

}  // namespace rigger::console
