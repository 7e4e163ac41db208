#include "model_replacement.hpp"

#include <cmath>
#include <sstream>

#include "planner.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

// cad::same_signature's default tolerances: the world model resolves with them.
constexpr double kToleranceM = 1e-6;
constexpr double kToleranceRad = 1e-6;

double distance(const json& a, const json& b) {
  if (!a.is_array() || !b.is_array() || a.size() != 3 || b.size() != 3) return INFINITY;
  double sum = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!a[i].is_number() || !b[i].is_number()) return INFINITY;
    const double d = a[i].get<double>() - b[i].get<double>();
    sum += d * d;
  }
  return std::sqrt(sum);
}

bool same_signature(const json& a, const json& b) {
  if (!a.is_object() || !b.is_object() || a.value("type", "") != b.value("type", "")) return false;
  const json ra = a.value("radius_m", json(0.0)), rb = b.value("radius_m", json(0.0));
  return distance(a.value("centroid_m", json()), b.value("centroid_m", json())) <= kToleranceM &&
         distance(a.value("direction", json()), b.value("direction", json())) <= kToleranceRad && ra.is_number() &&
         rb.is_number() && std::abs(ra.get<double>() - rb.get<double>()) <= kToleranceM;
}

std::string vector_text(const json& v) {
  if (!v.is_array() || v.size() != 3) return "?";
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "[";
  for (std::size_t i = 0; i < 3; ++i) out << (i ? ", " : "") << (v[i].is_number() ? v[i].get<double>() * 1000.0 : NAN);
  out << "] mm";
  return out.str();
}

/// "" when `ref` resolves in `features`, else why not (as cad::resolve: the index with the same signature,
/// or the only entity with it).
std::string unresolved(const json& ref, const json& features) {
  if (!ref.is_object()) return "not a reference";
  const std::string kind = ref.value("kind", "");
  const char* list = kind == "face" ? "faces" : kind == "edge" ? "edges" : "vertices";
  const json all = features.value(list, json::array());
  const json& sig = ref.contains("signature") ? ref["signature"] : json();
  const json index = ref.value("index", json(-1));
  if (index.is_number_integer() && index.get<long long>() >= 0 && index.get<std::size_t>() < all.size() &&
      same_signature(all[index.get<std::size_t>()].value("signature", json()), sig))
    return "";
  int matches = 0;
  for (const json& e : all)
    if (same_signature(e.value("signature", json()), sig)) ++matches;
  if (matches == 1) return "";
  return kind + " " + index.dump() + " (" + sig.value("type", "?") + " at " + vector_text(sig.value("centroid_m", json())) +
         ") is not in the new model" + (matches > 1 ? " once: " + std::to_string(matches) + " entities have its signature" : "");
}

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

/// Why `rule` no longer holds on the new model ("" when it does).
std::string stale(const json& rule, bool own, const json& features) {
  for (const auto& [key, ref] : references(rule, own)) {
    const std::string why = unresolved(*ref, features);
    if (!why.empty()) return key + ": " + why;
  }
  return "";
}

}  // namespace

ReplaceRequest parse_replace_request(const json& body) {
  if (!body.is_object()) throw PlannerError{"", "expected a JSON object {model, object}"};
  ReplaceRequest r;
  const std::string model = body.value("model", json()).is_string() ? body["model"].get<std::string>() : "";
  if (model.rfind("sha256:", 0) != 0 || model.size() != 7 + 64)
    throw PlannerError{"/model", "expected \"sha256:<hex>\", the imported file's model"};
  r.sha256 = model.substr(7);
  r.object = body.value("object", json()).is_string() ? body["object"].get<std::string>() : "";
  if (r.object.empty() || r.object.size() > 64) throw PlannerError{"/object", "expected the id of the object whose model it replaces"};
  r.comment = body.value("comment", json()).is_string() ? body["comment"].get<std::string>().substr(0, 200) : "";
  return r;
}

std::string replaced_model_name(const std::string& id, const std::string& sha256) {
  return "imported/" + id + "-" + sha256.substr(0, 12) + ".step";
}

Replacement cell_with_replaced_model(const json& cell, const ReplaceRequest& request, const json& features) {
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

  // Whether one feature's rule still holds on the new model (a feature without a rule does), recorded as
  // kept or dropped.
  const auto holds = [&](const std::string& name, const json& feature, bool own) {
    if (!feature.is_object() || !feature.contains("cad")) return true;
    const std::string why = stale(feature["cad"], own, features);
    if (why.empty())
      out.kept.push_back(name);
    else
      out.dropped.push_back({name, why});
    return why.empty();
  };
  for (json& e : out.cell["entities"]) {
    if (!e.is_object() || !e.contains("features") || !e["features"].is_object()) continue;
    const std::string id = e.value("id", "");
    json& f = e["features"];
    const bool own = &e == object;
    if (own) {
      for (const char* list : {"grasp_frames", "approach_waypoints", "screw_holes"}) {
        if (!f.contains(list) || !f[list].is_array()) continue;
        json kept = json::array();
        for (const json& item : f[list])
          if (holds(id + "/" + item.value("id", "?"), item, true)) kept.push_back(item);
        f[list] = kept;
      }
    }
    // The object's own insertion refers to its faces; another part's insertion into it, to the target's
    // (the cell file refuses an insertion into itself).
    if (f.contains("insertion") && f["insertion"].is_object() &&
        (own || f["insertion"].value("target", "") == request.object) && !holds(id + "/insertion", f["insertion"], own))
      f.erase("insertion");
  }
  return out;
}

}  // namespace rigger::console
