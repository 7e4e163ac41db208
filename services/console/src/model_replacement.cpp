#include "model_replacement.hpp"

#include <set>

#include "planner.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

/// Every reference of a rule: {what it is, the reference}; `own`: those into the rule's own model, else
/// those into its insertion target's.
std::vector<std::pair<std::string, const json*>> references(const json& rule, bool own) {
  std::vector<std::pair<std::string, const json*>> out;
  const auto add = [&](const char* key, const json& of) {
    if (of.is_object() && of.contains(key)) out.emplace_back(key, &of[key]);
  };
  if (own) {
    for (const char* key : {"face", "x_edge", "hole"}) add(key, rule);
  } else {
    add("target_face", rule);
  }
  if (rule.contains("pins") && rule["pins"].is_array())
    for (const json& pin : rule["pins"]) add(own ? "hole" : "target_hole", pin);
  return out;
}

}  // namespace

ReplaceRequest parse_replace_request(const json& body) {
  if (!body.is_object()) throw PlannerError{"", "expected a JSON object {model, object}"};
  ReplaceRequest r;
  r.sha256 = imported_model_sha256(body);
  r.object = body.value("object", json()).is_string() ? body["object"].get<std::string>() : "";
  if (r.object.empty() || r.object.size() > 64) throw PlannerError{"/object", "expected the id of the object whose model it replaces"};
  r.comment = body.value("comment", json()).is_string() ? body["comment"].get<std::string>().substr(0, 200) : "";
  return r;
}

std::string replaced_model_name(const std::string& id, const std::string& sha256) {
  return "imported/" + id + "-" + sha256.substr(0, 12) + ".step";
}

Replacement cell_with_replaced_model(const json& cell, const ReplaceRequest& request, const Resolver& resolve) {
  Replacement out;
  out.cell = cell;
  json* object = nullptr;
  for (json& e : out.cell["entities"])
    if (e.is_object() && e.value("id", "") == request.object) object = &e;
  if (object == nullptr) throw PlannerError{"/object", "the running cell revision has no entity \"" + request.object + "\""};
  json& model = (*object)["model"];
  if (!model.is_object() || !model.contains("step"))
    throw PlannerError{"/object", "\"" + request.object + "\" is not given by a STEP model: nothing to replace"};
  if (model.value("sha256", "") == request.sha256)
    throw PlannerError{"/model", "\"" + request.object + "\" has this model already (sha256 " + request.sha256.substr(0, 12) + ")"};
  model["step"] = replaced_model_name(request.object, request.sha256);
  model["sha256"] = request.sha256;

  // Every rule into the model: the object's own grasp frames, approach waypoints, screw holes and
  // insertion, and other parts' insertions into it (the cell file refuses an insertion into itself).
  struct Rule {
    std::string name;  ///< "<entity>/<feature>"
    json* feature;
    bool own;
    std::vector<std::pair<std::string, const json*>> refs;
  };
  std::vector<Rule> rules;
  const auto add = [&](std::string name, json& feature, bool own) {
    if (feature.is_object() && feature.contains("cad"))  // a feature without a rule holds
      rules.push_back({std::move(name), &feature, own, references(feature["cad"], own)});
  };
  for (json& e : out.cell["entities"]) {
    if (!e.is_object() || !e.contains("features") || !e["features"].is_object()) continue;
    const std::string id = e.value("id", "");
    json& f = e["features"];
    const bool own = &e == object;
    if (own)
      for (const char* list : {"grasp_frames", "approach_waypoints", "screw_holes"})
        if (f.contains(list) && f[list].is_array())
          for (json& item : f[list]) add(id + "/" + item.value("id", "?"), item, true);
    if (f.contains("insertion") && f["insertion"].is_object() && (own || f["insertion"].value("target", "") == request.object))
      add(id + "/insertion", f["insertion"], own);
  }

  // One question to the CAD service for all of them; a rule holds when each of its references resolves.
  std::vector<json> asked;
  for (const Rule& r : rules)
    for (const auto& ref : r.refs) asked.push_back(*ref.second);
  const std::vector<std::string> why = resolve(asked);
  if (why.size() != asked.size())
    throw PlannerError{"/model", "the CAD service resolved " + std::to_string(why.size()) + " of " +
                                     std::to_string(asked.size()) + " references"};
  std::size_t at = 0;
  std::set<const json*> stale;
  for (const Rule& r : rules) {
    std::string first;
    for (const auto& [key, ref] : r.refs) {
      if (first.empty() && !why[at].empty()) first = key + ": " + why[at];
      ++at;
    }
    if (first.empty()) {
      out.kept.push_back(r.name);
    } else {
      out.dropped.push_back({r.name, first});
      stale.insert(r.feature);
    }
  }
  for (json& e : out.cell["entities"]) {
    if (!e.is_object() || !e.contains("features") || !e["features"].is_object()) continue;
    json& f = e["features"];
    for (const char* list : {"grasp_frames", "approach_waypoints", "screw_holes"}) {
      if (!f.contains(list) || !f[list].is_array()) continue;
      json kept = json::array();
      for (json& item : f[list])
        if (stale.count(&item) == 0) kept.push_back(std::move(item));
      f[list] = std::move(kept);
    }
    if (f.contains("insertion") && stale.count(&f["insertion"]) != 0) f.erase("insertion");
  }
  return out;
}

}  // namespace rigger::console
