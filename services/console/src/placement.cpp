#include "placement.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "rigger/cell_config/cell_types.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr int kMaxParents = 64;  // a longer chain is a cycle

/// A face-rule frame request from the fields of `body` (the object's, or the support's under "/onto").
FrameRequest face_request(const json& body, const std::string& where) {
  json frame = {{"rule", "face"}};
  for (const char* key : {"model", "face", "point_m"})
    if (body.contains(key)) frame[key] = body[key];
  try {
    return parse_frame_request(frame);
  } catch (const PlannerError& e) {
    throw PlannerError{where + e.pointer, e.message};
  }
}

const json* entity_in(const json& cell, const std::string& id) {
  const auto entities = cell.find("entities");
  if (entities == cell.end() || !entities->is_array()) return nullptr;
  for (const json& e : *entities)
    if (e.is_object() && e.value("id", "") == id) return &e;
  return nullptr;
}

Eigen::Isometry3d pose_of(const json& entity) {
  const json pose = entity.value("pose", json::object());
  const json p = pose.value("position_m", json::array({0, 0, 0}));
  const json r = pose.value("rpy_deg", json::array({0, 0, 0}));
  if (!p.is_array() || p.size() != 3 || !r.is_array() || r.size() != 3)
    throw PlannerError{"", "the cell's entity \"" + entity.value("id", "") + "\" has no pose {position_m, rpy_deg}"};
  return cell::pose_from_position_rpy_deg({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()},
                                          {r[0].get<double>(), r[1].get<double>(), r[2].get<double>()});
}

/// The entity's pose in the world and the ids on its way there (itself first).
Eigen::Isometry3d world_pose(const json& cell, const std::string& id, std::vector<std::string>* chain = nullptr) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::string at = id;
  for (int hops = 0; at != "world"; ++hops) {
    const json* e = entity_in(cell, at);
    if (e == nullptr) throw PlannerError{"", "the running cell has no entity \"" + at + "\""};
    if (hops >= kMaxParents) throw PlannerError{"", "the parents of \"" + id + "\" do not reach \"world\""};
    if (chain) chain->push_back(at);
    pose = pose_of(*e) * pose;
    at = e->value("parent", "world");
  }
  return pose;
}

}  // namespace

Eigen::Isometry3d world_pose_of(const json& cell, const std::string& id) { return world_pose(cell, id); }

PlaceRequest parse_place_request(const json& body) {
  PlaceRequest r;
  r.own = face_request(body, "");
  const auto onto = body.find("onto");
  if (onto == body.end() || !onto->is_object())
    throw PlannerError{"/onto", "expected the face to place it on: {\"model\": \"object:<entity>\", \"face\", \"point_m\"}"};
  r.onto = face_request(*onto, "/onto");
  if (r.onto.entity == r.own.entity) throw PlannerError{"/onto/model", "an object cannot be placed on itself"};
  const auto turn = body.find("turn_deg");
  if (turn != body.end()) {
    if (!turn->is_number() || !std::isfinite(turn->get<double>()) || std::abs(turn->get<double>()) > 360.0)
      throw PlannerError{"/turn_deg", "expected the turn about the support's normal in degrees, -360 to 360"};
    r.turn_deg = turn->get<double>();
  }
  const auto edge = [](const json& at, const std::string& pointer) -> std::optional<int> {
    const auto e = at.find("edge");
    if (e == at.end() || e->is_null()) return std::nullopt;
    if (!e->is_number_integer() || e->get<long long>() < 0 || e->get<long long>() > 1'000'000)
      throw PlannerError{pointer, "expected the picked edge's index in the model (integer ≥ 0)"};
    return e->get<int>();
  };
  r.own_edge = edge(body, "/edge");
  r.onto_edge = edge(*onto, "/onto/edge");
  if (r.own_edge.has_value() != r.onto_edge.has_value())
    throw PlannerError{r.own_edge ? "/onto/edge" : "/edge", "expected an edge of each part, or none"};
  const auto offset = body.find("offset_m");
  if (offset != body.end()) {
    if (!offset->is_number() || !std::isfinite(offset->get<double>()) || std::abs(offset->get<double>()) > 10.0)
      throw PlannerError{"/offset_m", "expected the distance along the support's face in metres, -10 to 10"};
    r.offset_m = offset->get<double>();
  }
  const auto localized = body.find("localized");
  if (localized != body.end()) {
    if (!localized->is_boolean())
      throw PlannerError{"/localized", "expected true (the pose is known) or false (a Localize skill finds it at run time)"};
    r.localized = localized->get<bool>();
  }
  const auto comment = body.find("comment");
  if (comment != body.end() && comment->is_string()) r.comment = comment->get<std::string>().substr(0, 500);
  return r;
}

Eigen::Isometry3d frame_from_cad(const json& cad_result) {
  const json frame = cad_result.value("frame", json());
  const json position = frame.is_object() ? frame.value("position_m", json()) : json();
  const json rotation = frame.is_object() ? frame.value("rotation", json()) : json();
  const auto numbers = [](const json& v) {
    if (!v.is_array() || v.size() != 3) return false;
    for (const json& x : v)
      if (!x.is_number() || !std::isfinite(x.get<double>())) return false;
    return true;
  };
  bool ok = numbers(position) && rotation.is_array() && rotation.size() == 3;
  for (std::size_t i = 0; ok && i < 3; ++i) ok = numbers(rotation[i]);
  if (!ok) throw PlannerError{"", "the CAD service's answer holds no frame (position_m and a 3x3 rotation)"};
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i) {
    t.translation()(i) = position[i].get<double>();
    for (int j = 0; j < 3; ++j) t.linear()(i, j) = rotation[i][j].get<double>();
  }
  return t;
}

Eigen::Isometry3d placed_on(const Eigen::Isometry3d& onto_face, const Eigen::Isometry3d& own_face, double turn_deg) {
  // Turned about the support's normal, then flipped about x so that the object's face looks down on it.
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(turn_deg * kDeg, Eigen::Vector3d::UnitZ()));
  const Eigen::Isometry3d flip(Eigen::AngleAxisd(180.0 * kDeg, Eigen::Vector3d::UnitX()));
  return onto_face * turn * flip * own_face.inverse();
}

namespace {

// The angle (rad) of `direction` in the xy plane of `face`, or a PlannerError at `pointer` when it leaves
// the plane by more than a milliradian.
double angle_in_face(const Eigen::Isometry3d& face, const Eigen::Vector3d& direction, const std::string& pointer) {
  const Eigen::Vector3d d = face.linear().transpose() * direction.normalized();
  if (std::abs(d.z()) > std::sin(1e-3))
    throw PlannerError{pointer, "the edge does not lie in the picked face's plane (" +
                                    std::to_string(std::asin(std::min(1.0, std::abs(d.z()))) / kDeg).substr(0, 5) +
                                    "° out of it): pick an edge of that face"};
  return std::atan2(d.y(), d.x());
}

}  // namespace

double edge_turn_deg(const Eigen::Isometry3d& onto_face, const Eigen::Vector3d& onto_edge,
                     const Eigen::Isometry3d& own_face, const Eigen::Vector3d& own_edge) {
  // The flip about x mirrors the object's face angles (a -> -a); the turn brings -a_own onto a_onto.
  const double onto = angle_in_face(onto_face, onto_edge, "/onto/edge");
  const double own = angle_in_face(own_face, own_edge, "/edge");
  return std::remainder(onto + own, 2 * 3.14159265358979323846) / kDeg;
}

Eigen::Isometry3d offset_along(const Eigen::Isometry3d& onto_face, const std::optional<Eigen::Vector3d>& direction,
                               double offset_m) {
  Eigen::Vector3d d = onto_face.linear().col(0);
  if (direction) {
    const Eigen::Vector3d n = onto_face.linear().col(2);
    const Eigen::Vector3d in_plane = *direction - direction->dot(n) * n;
    if (in_plane.norm() > 1e-9) d = in_plane.normalized();
  }
  Eigen::Isometry3d moved = onto_face;
  moved.translation() += offset_m * d;
  return moved;
}

json position_rpy(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d& R = pose.linear();
  // R = Rz(yaw) Ry(pitch) Rx(roll): R20 = -sin(pitch); away from ±90° roll and yaw follow.
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  double roll = 0.0, yaw = 0.0;
  if (std::abs(R(2, 0)) < 1.0 - 1e-12) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {
    yaw = std::atan2(-R(0, 1), R(1, 1));  // gimbal lock: only roll ∓ yaw is defined; roll = 0
  }
  // Whole-micro-degree and nanometre rounding keeps 1e-17 noise (and -0) out of the text; dividing the
  // rounded integer by the scale gives the double nearest the decimal (0.3, not 0.30000000000000004).
  const auto tidy = [](double v, double scale) { const double r = std::round(v * scale) / scale; return r == 0.0 ? 0.0 : r; };
  json p = json::array(), rpy = json::array();
  for (int i = 0; i < 3; ++i) p.push_back(tidy(pose.translation()(i), 1e9));
  for (double a : {roll, pitch, yaw}) rpy.push_back(tidy(a / kDeg, 1e6));
  return {{"position_m", p}, {"rpy_deg", rpy}};
}

json cell_with_placement(const json& cell, const std::string& entity, const std::string& support,
                         const Eigen::Isometry3d& support_T_entity, std::optional<bool> localized) {
  const json* moved = entity_in(cell, entity);
  if (moved == nullptr) throw PlannerError{"/model", "the running cell has no entity \"" + entity + "\""};
  std::vector<std::string> support_chain;
  const Eigen::Isometry3d world_T_support = world_pose(cell, support, &support_chain);
  for (const std::string& id : support_chain)
    if (id == entity)
      throw PlannerError{"/onto/model", "\"" + support + "\" is carried by \"" + entity + "\": it cannot carry it"};
  const std::string parent = moved->value("parent", "world");
  const Eigen::Isometry3d world_T_parent = parent == "world" ? Eigen::Isometry3d::Identity() : world_pose(cell, parent);
  const Eigen::Isometry3d parent_T_entity = world_T_parent.inverse() * world_T_support * support_T_entity;
  json out = cell;
  for (json& e : out["entities"])
    if (e.is_object() && e.value("id", "") == entity) {
      e["pose"] = position_rpy(parent_T_entity);
      if (localized) e["localized"] = *localized;
    }
  return out;
}

namespace {

/// kg/m³ of the materials a loose imported part may be made of.
std::optional<double> density_of(const std::string& material) {
  if (material == "steel") return 7850.0;
  if (material == "aluminium") return 2700.0;
  if (material == "plastic") return 1200.0;
  return std::nullopt;
}

bool plain_id(const std::string& id) {
  if (id.empty() || id.size() > 64) return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

}  // namespace

AddRequest parse_add_request(const json& body) {
  if (!body.is_object()) throw PlannerError{"", "expected a JSON object {model, id, material}"};
  AddRequest r;
  r.sha256 = imported_model_sha256(body);
  r.id = body.value("id", json()).is_string() ? body["id"].get<std::string>() : "";
  if (!plain_id(r.id))
    throw PlannerError{"/id", "expected a name of 1 to 64 letters, digits, '_' or '-', got \"" + r.id.substr(0, 64) + "\""};
  r.material = body.value("material", json()).is_string() ? body["material"].get<std::string>() : "";
  if (r.material != "fixed" && !density_of(r.material))
    throw PlannerError{"/material", "expected \"steel\", \"aluminium\", \"plastic\" or \"fixed\", got \"" +
                                        r.material.substr(0, 32) + "\""};
  r.comment = body.value("comment", json()).is_string() ? body["comment"].get<std::string>() : "";
  return r;
}

NodeRequest parse_node_request(const json& body) {
  if (!body.is_object()) throw PlannerError{"", "expected a JSON object {model, node}"};
  NodeRequest r;
  r.sha256 = imported_model_sha256(body);
  const json node = body.value("node", json());
  if (!node.is_array() || node.size() > 32)
    throw PlannerError{"/node", "expected the node's path in the product tree: an array of at most 32 component indices"};
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].is_number_integer() || node[i].get<long long>() < 0 || node[i].get<long long>() > 100'000)
      throw PlannerError{"/node/" + std::to_string(i), "expected a component index (0 to 100000)"};
    r.node.push_back(node[i].get<int>());
  }
  return r;
}

std::string imported_model_name(const std::string& id) { return "imported/" + id + ".step"; }

double lowest_vertex_z(const json& features) {
  std::optional<double> lowest;
  for (const json& v : features.value("vertices", json::array())) {
    const json p = v.value("point_m", json());
    if (p.is_array() && p.size() == 3 && p[2].is_number())
      lowest = std::min(lowest.value_or(p[2].get<double>()), p[2].get<double>());
  }
  if (!lowest) throw PlannerError{"/model", "the CAD service gave no vertex of the model: its lowest point is unknown"};
  return *lowest;
}

json cell_with_new_object(const json& cell, const AddRequest& request, double lowest_z_m) {
  if (entity_in(cell, request.id) != nullptr)
    throw PlannerError{"/id", "the cell has an entity \"" + request.id + "\" already: choose another name"};
  double beyond_x = 0.0;
  for (const json& e : cell.value("entities", json::array())) {
    if (!e.is_object() || e.value("parent", "world") != "world" || !e.contains("pose")) continue;
    beyond_x = std::max(beyond_x, pose_of(e).translation().x());
  }
  json model = {{"frame", "the STEP file's origin"},
                {"step", imported_model_name(request.id)},
                {"sha256", request.sha256}};
  const std::optional<double> density = density_of(request.material);
  if (density) {
    model["density_kg_m3"] = *density;
  } else {
    model["static"] = true;
  }
  const double z = -lowest_z_m + (density ? 1e-3 : 0.0);
  json out = cell;
  out["entities"].push_back({{"id", request.id},
                             {"kind", "object"},
                             {"parent", "world"},
                             {"pose", {{"position_m", {beyond_x + 1.0, 0.0, z}}, {"rpy_deg", {0, 0, 0}}}},
                             {"model", model}});
  return out;
}

namespace {

/// The lowest world z of the model's vertices with the model at `world_T_model`.
double lowest_world_z(const json& features, const Eigen::Isometry3d& world_T_model, const std::string& id) {
  std::optional<double> lowest;
  for (const json& v : features.value("vertices", json::array())) {
    const json p = v.value("point_m", json());
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) continue;
    const double z = (world_T_model * Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>())).z();
    lowest = std::min(lowest.value_or(z), z);
  }
  if (!lowest) throw PlannerError{"/model", "the CAD service gave no vertex of \"" + id + "\": its lowest point is unknown"};
  return *lowest;
}

}  // namespace

json cell_with_load_exchanged(const json& cell, const std::string& part, const Eigen::Vector3d& attachment_m,
                              const json& part_features, const std::string& holder, const json& holder_features) {
  const json* held = entity_in(cell, holder);
  if (held == nullptr || entity_in(cell, part) == nullptr)
    throw PlannerError{"/model", "the running cell has no entity \"" + (held == nullptr ? holder : part) + "\""};
  const json hook = held->value("features", json::object()).value("rope_attachment", json());
  if (!hook.is_object()) throw PlannerError{"/model", "\"" + holder + "\" has no rope attachment to take"};
  const Eigen::Isometry3d world_T_holder = world_pose(cell, holder);
  const Eigen::Isometry3d world_T_part = world_pose(cell, part);
  const Eigen::Vector3d hook_world = world_T_holder * pose_of(json{{"pose", hook}}).translation();
  const double holder_low = lowest_world_z(holder_features, world_T_holder, holder);
  const double part_low = lowest_world_z(part_features, world_T_part, part);

  Eigen::Isometry3d hung = world_T_part;  // orientation kept
  hung.translation().setZero();
  const Eigen::Vector3d attachment = hung * attachment_m;
  const double hung_low = lowest_world_z(part_features, hung, part);
  hung.translation() = Eigen::Vector3d(hook_world.x() - attachment.x(), hook_world.y() - attachment.y(), holder_low - hung_low);

  Eigen::Isometry3d set_down = world_T_holder;
  set_down.translation() = world_T_part.translation();
  set_down.translation().z() += part_low - lowest_world_z(holder_features, set_down, holder);
  return cell_with_placement(cell_with_placement(cell, part, "world", hung, false), holder, "world", set_down);
}

}  // namespace rigger::console
