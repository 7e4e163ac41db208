#include "planner_declare.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <vector>

namespace rigger::console {

using nlohmann::json;

namespace {

constexpr double kInPlane = 1e-3;       // rad: the derivation's own tolerance for x_edge in the face plane
constexpr double kSameDiameter = 1e-5;  // m
constexpr double kSameAxis = 1e-6;      // 1 - cos of the angle between two hole axes
constexpr double kSameFace = 1e-4;      // m: entries this close to the picked hole's entry plane

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

double dot(const json& a, const json& b) {
  return a[0].get<double>() * b[0].get<double>() + a[1].get<double>() * b[1].get<double>() +
         a[2].get<double>() * b[2].get<double>();
}

/// The CAD features' entry `index` of `list` ("faces", "edges", "holes"), or a PlannerError at `pointer`.
const json& entry(const json& cad, const char* list, const json& index, const std::string& pointer,
                  const std::string& model) {
  if (!index.is_number_integer() || index.get<long long>() < 0)
    throw PlannerError{pointer, std::string("expected an index into the model's ") + list + " (integer ≥ 0)"};
  static const json none = json::array();
  const json& all = cad.contains(list) && cad[list].is_array() ? cad[list] : none;
  const auto i = index.get<std::size_t>();
  if (i >= all.size())
    throw PlannerError{pointer, model + " has " + std::to_string(all.size()) + " " + list + ", no " +
                                    std::string(list, std::string(list).size() - 1) + " " + std::to_string(i)};
  return all[i];
}

json reference(const char* kind, const json& e) {
  return {{"kind", kind}, {"index", e.at("index")}, {"signature", e.at("signature")}};
}

/// The `face` rule of a grasp frame or an approach waypoint.
json face_rule(const DeclareRequest& r, const json& cad) {
  const json& p = r.picks;
  if (!p.contains("face")) throw PlannerError{"/face", "expected the picked face (its index in the model)"};
  const json& face = entry(cad, "faces", p["face"], "/face", r.model);
  if (face.at("signature").value("type", "") != "plane" || !face.contains("normal"))
    throw PlannerError{"/face", "face " + face.at("index").dump() + " of " + r.model + " is a " +
                                    face.at("signature").value("type", "?") + ", not a plane: a frame needs a planar face"};
  json rule = {{"rule", "face"}, {"z", "into"}, {"face", reference("face", face)}};
  if (p.contains("x_edge") && !p["x_edge"].is_null()) {
    const json& edge = entry(cad, "edges", p["x_edge"], "/x_edge", r.model);
    const json& sig = edge.at("signature");
    if (sig.value("type", "") != "line")
      throw PlannerError{"/x_edge", "edge " + edge.at("index").dump() + " is a " + sig.value("type", "?") +
                                        ", not a straight edge: x needs a direction"};
    const double along_normal = std::abs(dot(sig.at("direction"), face.at("normal")));
    if (along_normal > std::sin(kInPlane))
      throw PlannerError{"/x_edge", "edge " + edge.at("index").dump() + " does not lie in face " + face.at("index").dump() +
                                        "'s plane (" + std::to_string(std::asin(std::min(1.0, along_normal)) * 180 / M_PI).substr(0, 5) +
                                        "° out of it): pick an edge of the face for x"};
    rule["x_edge"] = reference("edge", edge);
    if (p.value("x_reversed", false)) rule["x_reversed"] = true;
  }
  if (r.kind == "approach_waypoint") {
    const auto s = p.find("standoff_m");
    if (s == p.end() || !s->is_number() || !(s->get<double>() > 0.0) || s->get<double>() > 2.0)
      throw PlannerError{"/standoff_m", "expected the stand-off out of the face in metres, > 0 and at most 2"};
    rule["standoff_m"] = *s;
  }
  return rule;
}

json screw_of(const json& s, const std::string& pointer) {
  if (!s.is_object() || !s.contains("screw_type") || !s["screw_type"].is_string() || s["screw_type"].get<std::string>().empty() ||
      s["screw_type"].get<std::string>().size() > 64 || !s.contains("torque_nm") || !s["torque_nm"].is_number() ||
      !(s["torque_nm"].get<double>() > 0.0) || s["torque_nm"].get<double>() > 1000.0)
    throw PlannerError{pointer, "expected {\"screw_type\": \"M12x40\", \"torque_nm\": > 0 and at most 1000}"};
  return s;
}

/// The holes the request names: the picked one, and with "like" every hole of the same diameter and
/// axis whose entry lies on the picked hole's entry plane, in index order (holes of another diameter on
/// that plane are left for a pattern of their own).
std::vector<const json*> picked_holes(const DeclareRequest& r, const json& cad) {
  const json& p = r.picks;
  if (!p.contains("hole")) throw PlannerError{"/hole", "expected the picked hole (its index in the model's holes)"};
  const json& first = entry(cad, "holes", p["hole"], "/hole", r.model);
  std::vector<const json*> out{&first};
  if (!p.value("like", false)) return out;
  for (const json& h : cad["holes"]) {
    if (&h == &first) continue;
    const json d = json::array({h["entry_m"][0].get<double>() - first["entry_m"][0].get<double>(),
                                h["entry_m"][1].get<double>() - first["entry_m"][1].get<double>(),
                                h["entry_m"][2].get<double>() - first["entry_m"][2].get<double>()});
    if (dot(h["axis"], first["axis"]) < 1.0 - kSameAxis || std::abs(dot(d, first["axis"])) > kSameFace) continue;
    // Holes of another diameter on the face are another pattern (another screw): picked on their own.
    if (std::abs(h["diameter_m"].get<double>() - first["diameter_m"].get<double>()) > kSameDiameter) continue;
    out.push_back(&h);
  }
  return out;
}

json screw_hole_rules(const DeclareRequest& r, const json& cad) {
  const std::vector<const json*> holes = picked_holes(r, cad);
  const json& p = r.picks;
  if (!p.contains("screw")) throw PlannerError{"/screw", "expected the screw for the holes: {\"screw_type\", \"torque_nm\"}"};
  const json screw = screw_of(p["screw"], "/screw");
  const json screws = p.value("screws", json::array());
  if (!screws.is_array() || (!screws.empty() && screws.size() != holes.size()))
    throw PlannerError{"/screws", "expected one screw per hole (" + std::to_string(holes.size()) +
                                      ") in hole order, or none (each gets \"screw\")"};
  json out = json::array();
  for (std::size_t i = 0; i < holes.size(); ++i) {
    const json& h = *holes[i];
    const json& faces = h.at("faces");
    if (!faces.is_array() || faces.empty()) throw PlannerError{"/hole", "the CAD service gives hole " + h["index"].dump() + " no face"};
    const json& face = entry(cad, "faces", faces[0], "/hole", r.model);
    const json s = screws.empty() ? screw : screw_of(screws[i], "/screws/" + std::to_string(i));
    out.push_back({{"id", r.name + std::to_string(i + 1)},
                   {"cad", {{"rule", "hole"}, {"hole", reference("face", face)}}},
                   {"screw_type", s["screw_type"]},
                   {"torque_nm", s["torque_nm"]}});
  }
  return out;
}

/// One cylindrical face of hole `index` of a model, as the cell file's reference (`pointer`: the request's key).
json hole_face_reference(const json& cad, const json& index, const std::string& pointer, const std::string& model) {
  const json& hole = entry(cad, "holes", index, pointer, model);
  const json& faces = hole.at("faces");
  if (!faces.is_array() || faces.empty())
    throw PlannerError{pointer, "the CAD service gives hole " + hole["index"].dump() + " of " + model + " no face"};
  return reference("face", entry(cad, "faces", faces[0], pointer, model));
}

/// The insertion: the picked face of this object lies on the picked face of the target (the cell file's
/// `mate_faces` rule); both planes. With pins (one or two pairs of a hole of each), the holes line up.
json insertion_rule(const DeclareRequest& r, const json& cad, const json& target_cad) {
  const json& p = r.picks;
  const auto plane = [&](const json& features, const json& index, const std::string& pointer, const std::string& model) -> const json& {
    const json& face = entry(features, "faces", index, pointer, model);
    if (face.at("signature").value("type", "") != "plane")
      throw PlannerError{pointer, "face " + face.at("index").dump() + " of " + model + " is a " +
                                      face.at("signature").value("type", "?") + ", not a plane: faces that mate are planes"};
    return face;
  };
  if (!p.contains("face")) throw PlannerError{"/face", "expected the picked face of " + r.entity + " that mates"};
  if (!p.contains("target") || !p["target"].is_object() || !p["target"].contains("face"))
    throw PlannerError{"/target/face", "expected the picked face of the part it is inserted into"};
  const json& own = plane(cad, p["face"], "/face", r.model);
  const json& onto = plane(target_cad, p["target"]["face"], "/target/face", "object:" + r.target);
  json rule = {{"rule", "mate_faces"}, {"face", reference("face", own)}, {"target_face", reference("face", onto)}};
  if (p.contains("pins")) {
    const json& pins = p["pins"];
    if (!pins.is_array() || pins.empty() || pins.size() > 2)
      throw PlannerError{"/pins", "expected one or two pins: [{\"hole\": a hole of " + r.entity +
                                      ", \"target_hole\": a hole of " + r.target + "}]"};
    for (std::size_t i = 0; i < pins.size(); ++i) {
      const std::string at = "/pins/" + std::to_string(i);
      if (!pins[i].is_object() || !pins[i].contains("hole") || !pins[i].contains("target_hole"))
        throw PlannerError{at, "expected {\"hole\", \"target_hole\"}: a hole of each part"};
      rule["pins"].push_back({{"hole", hole_face_reference(cad, pins[i]["hole"], at + "/hole", r.model)},
                              {"target_hole", hole_face_reference(target_cad, pins[i]["target_hole"], at + "/target_hole",
                                                                  "object:" + r.target)}});
    }
  }
  return {{"target", r.target}, {"cad", std::move(rule)}};
}

}  // namespace

DeclareRequest parse_declare_request(const json& body) {
  DeclareRequest r;
  if (!body.is_object()) throw PlannerError{"", "expected {\"model\", \"kind\", \"name\", ...the picks}"};
  const auto model = body.find("model");
  const std::string prefix = "object:";
  if (model == body.end() || !model->is_string() || model->get<std::string>().rfind(prefix, 0) != 0 ||
      model->get<std::string>().size() == prefix.size() || model->get<std::string>().size() > 200)
    throw PlannerError{"/model", "expected the model as \"object:<entity id>\", e.g. \"object:target\""};
  r.model = *model;
  r.entity = r.model.substr(prefix.size());
  r.picks = body;
  r.kind = body.value("kind", json()).is_string() ? body["kind"].get<std::string>() : "";
  static const std::set<std::string> kKinds = {"grasp_frame", "approach_waypoint", "screw_holes", "insertion",
                                               "rope_attachment", "marker"};
  if (kKinds.count(r.kind) == 0)
    throw PlannerError{"/kind", "expected the kind: \"grasp_frame\", \"approach_waypoint\", \"screw_holes\", "
                                "\"insertion\", \"rope_attachment\" or \"marker\""};
  // One of each per object, or named by their own fields: their name is their kind.
  if ((r.kind == "rope_attachment" || r.kind == "marker") && !body.contains("name")) r.picks["name"] = r.kind;
  if (r.kind == "insertion") {
    const json target = body.value("target", json::object());
    const json tm = target.is_object() ? target.value("model", json()) : json();
    if (!tm.is_string() || tm.get<std::string>().rfind(prefix, 0) != 0 || tm.get<std::string>().size() == prefix.size() ||
        tm.get<std::string>().size() > 200)
      throw PlannerError{"/target/model", "expected the part it is inserted into as \"object:<entity id>\""};
    r.target = tm.get<std::string>().substr(prefix.size());
    if (r.target == r.entity) throw PlannerError{"/target/model", "a part is not inserted into itself: pick a face of another part"};
    if (!body.contains("name")) r.picks["name"] = "insertion";  // one per object: its name is its kind
  }
  r.name = r.picks.value("name", json()).is_string() ? r.picks["name"].get<std::string>() : "";
  if (!valid_name(r.name))
    throw PlannerError{"/name", "expected a name of 1 to 64 letters, digits, '_' or '-'"};
  return r;
}

json declare_feature(const DeclareRequest& r, const json& cell, const json& cad, const json& target_cad) {
  json doc = cell;
  json* entity = nullptr;
  if (doc.contains("entities") && doc["entities"].is_array())
    for (json& e : doc["entities"])
      if (e.is_object() && e.value("id", "") == r.entity) entity = &e;
  if (entity == nullptr) throw PlannerError{"/model", "the running cell revision has no entity \"" + r.entity + "\""};
  json& features = (*entity)["features"];
  if (!features.is_object()) features = json::object();
  std::set<std::string> taken;
  for (const auto& [key, list] : features.items())
    if (list.is_array())
      for (const json& f : list)
        if (f.is_object() && f.contains("id") && f["id"].is_string()) taken.insert(f["id"].get<std::string>());

  if (r.kind == "insertion") {
    if (features.contains("insertion")) {
      throw PlannerError{"/kind", "\"" + r.entity + "\" has an insertion already (into \"" +
                                      features["insertion"].value("target", "?") + "\"): roll back its revision first"};
    }
    // The part goes into a fixture: a loose target would be pushed away (the physics refuses it).
    for (const json& e : doc["entities"])
      if (e.is_object() && e.value("id", "") == r.target &&
          !(e.contains("model") && e["model"].is_object() && e["model"].value("static", false)))
        throw PlannerError{"/target/model", "\"" + r.target + "\" is loose: a part is inserted into a fixed one "
                                            "(add it fixed, or declare the insertion into what holds it)"};
    const json rule = insertion_rule(r, cad, target_cad);
    features["insertion"] = rule;
    return {{"cell", std::move(doc)}, {"features", {r.entity + "/insertion"}}, {"rule", json::array({rule})}};
  }
  json added = json::array();
  std::string list;
  if (r.kind == "screw_holes") {
    list = "screw_holes";
    added = screw_hole_rules(r, cad);
  } else {
    list = r.kind == "grasp_frame" ? "grasp_frames" : "approach_waypoints";
    added.push_back({{"id", r.name}, {"cad", face_rule(r, cad)}});
  }
  json ids = json::array();
  for (const json& f : added) {
    const std::string id = f["id"];
    if (taken.count(id) != 0)
      throw PlannerError{"/name", "\"" + r.entity + "\" already has a feature \"" + id + "\": pick another name"};
    ids.push_back(r.entity + "/" + id);
  }
  json& target = features[list];
  if (!target.is_array()) target = json::array();
  for (const json& f : added) target.push_back(f);
  return {{"cell", std::move(doc)}, {"features", ids}, {"rule", added}};
}

}  // namespace rigger::console
