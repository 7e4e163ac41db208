#include "cad_service.hpp"

#include "rigger/base/bounded_json.hpp"
#include "rigger/cad/assembly.hpp"
#include "rigger/cad/cad_json.hpp"
#include "rigger/cad/frames.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace rigger::cad_service {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// How far above a part the rule "above_centre_of_mass" puts the sling's ring (metres).
constexpr double kSlingClearanceM = 0.02;

// A request error that is not the CAD library's: bad arguments, unknown model, forbidden path.
struct RequestError {
  std::string code;
  std::string message;
};

json parse_args(const std::string& text) {
  if (text.empty()) {
    return json::object();
  }
  // From another process: parsed with bounds (64 KiB, depth 16; picks are flat).
  JsonParseResult parsed = parse_json_bounded(text, {64U * 1024U, 16});
  if (!parsed.ok()) throw RequestError{"CAD_BAD_REQUEST", "args_json: " + parsed.error->to_string()};
  if (!parsed.value.is_object()) throw RequestError{"CAD_BAD_REQUEST", "args_json is not a JSON object"};
  return std::move(parsed.value);
}

Eigen::Vector3d point_arg(const json& args, const char* key) {
  const auto it = args.find(key);
  if (it == args.end() || !it->is_array() || it->size() != 3 || !(*it)[0].is_number() || !(*it)[1].is_number() ||
      !(*it)[2].is_number()) {
    throw RequestError{"CAD_BAD_REQUEST", std::string("args_json.") + key + " must be [x, y, z] in metres"};
  }
  return {(*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>()};
}

// An index given as a number, or a reference object (resolved against the model: stale references are
// refused with CAD_STALE_REFERENCE).
int entity_arg(const cad::Features& features, const json& value, cad::EntityKind kind, const std::string& what) {
  if (value.is_number_integer()) {
    return value.get<int>();
  }
  if (value.is_object()) {
    const cad::Reference ref = cad::reference_from_json(value);
    if (ref.kind != kind) {
      throw RequestError{"CAD_BAD_REQUEST", what + " must reference a " + std::string(cad::to_string(kind))};
    }
    return cad::resolve(features, ref);
  }
  throw RequestError{"CAD_BAD_REQUEST", what + " must be an index or a reference object"};
}

int int_arg(const json& args, const char* key) {
  const auto it = args.find(key);
  if (it == args.end() || !it->is_number_integer()) {
    throw RequestError{"CAD_BAD_REQUEST", std::string("args_json.") + key + " must be an integer"};
  }
  return it->get<int>();
}

// args_json.node of CAD_LOAD: the indices of the components taken from the root, at most `max_depth`.
cad::NodePath node_arg(const json& node, int max_depth) {
  if (!node.is_array() || node.size() > static_cast<std::size_t>(max_depth)) {
    throw RequestError{"CAD_BAD_REQUEST", "args_json.node must be an array of at most " + std::to_string(max_depth) +
                                              " component indices (the path from the root)"};
  }
  cad::NodePath path;
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].is_number_integer() || node[i].get<long long>() < 0 || node[i].get<long long>() > 100'000) {
      throw RequestError{"CAD_BAD_REQUEST", "args_json.node[" + std::to_string(i) + "] must be a component index (0 to 100000)"};
    }
    path.push_back(node[i].get<int>());
  }
  return path;
}

bool inside(const fs::path& path, const fs::path& dir) {
  std::error_code error;
  const fs::path file = fs::weakly_canonical(path, error);
  const fs::path root = fs::weakly_canonical(dir, error);
  const auto mismatch = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  return mismatch.first == root.end();
}

}  // namespace

CadService::CadService(CadServiceSettings settings) : settings_(std::move(settings)) {
  follow(cell::load_cell_file(settings_.cell_file), settings_.cell_file.parent_path());
}

void CadService::follow(const cell::CellFile& cell, const fs::path& folder) {
  std::map<std::string, std::string> objects;
  std::map<std::string, std::string> errors;
  std::map<std::string, std::string> status;
  std::map<std::string, fs::path> paths;
  for (const auto& entity : cell.entities) {
    if (!entity.model || entity.model->step.empty()) {
      continue;
    }
    const fs::path path = folder / entity.model->step;
    paths[entity.id] = path;
    if (std::find(settings_.allowed_dirs.begin(), settings_.allowed_dirs.end(), path.parent_path()) ==
        settings_.allowed_dirs.end())
      settings_.allowed_dirs.push_back(path.parent_path());
    const auto loaded = objects_.find(entity.id);
    const auto before = object_paths_.find(entity.id);
    if (loaded != objects_.end() && before != object_paths_.end() && before->second == path &&
        models_.count(loaded->second) != 0 &&
        (entity.model->step_sha256.empty() || entity.model->step_sha256 == loaded->second)) {
      objects[entity.id] = loaded->second;  // the same file as the running revision's: not read again
      status[entity.id] = "ok " + loaded->second;
      continue;
    }
    try {
      cad::Model model = cad::read_step_file(path, settings_.limits);
      if (const std::string stale = cell::stale_model_problem(*entity.model, model.sha256()); !stale.empty()) {
        errors[entity.id] = "CAD_STALE_MODEL\t" + stale;
        status[entity.id] = errors[entity.id];
        continue;
      }
      Entry& entry = add(std::move(model), true);
      objects[entity.id] = entry.model.sha256();
      status[entity.id] = "ok " + entry.model.sha256();
    } catch (const cad::CadError& error) {
      errors[entity.id] = std::string(cad::to_string(error.code())) + "\t" + error.what();
      status[entity.id] = errors[entity.id];
    }
  }
  objects_ = std::move(objects);
  object_errors_ = std::move(errors);
  object_status_ = std::move(status);
  object_paths_ = std::move(paths);
  // A model no object names any more is kept like a requested one: evicted oldest first.
  for (const auto& [sha, entry] : models_) {
    const bool named = std::any_of(objects_.begin(), objects_.end(), [&](const auto& o) { return o.second == sha; });
    if (!named && std::find(unpinned_.begin(), unpinned_.end(), sha) == unpinned_.end()) unpinned_.push_back(sha);
  }
  unpinned_.erase(std::remove_if(unpinned_.begin(), unpinned_.end(),
                                 [&](const std::string& sha) {
                                   return std::any_of(objects_.begin(), objects_.end(),
                                                      [&](const auto& o) { return o.second == sha; });
                                 }),
                  unpinned_.end());
  while (unpinned_.size() > settings_.max_models) {
    models_.erase(unpinned_.front());
    unpinned_.erase(unpinned_.begin());
  }
}

CadService::Entry& CadService::add(cad::Model model, bool pinned) {
  const std::string sha = model.sha256();
  auto it = models_.find(sha);
  if (it != models_.end()) {
    return it->second;
  }
  cad::Features features = cad::classify(model);
  it = models_.emplace(sha, Entry{std::move(model), std::move(features), std::nullopt}).first;
  if (!pinned) {
    unpinned_.push_back(sha);
    while (unpinned_.size() > settings_.max_models) {
      models_.erase(unpinned_.front());
      unpinned_.erase(unpinned_.begin());
    }
  }
  return models_.at(sha);
}

CadService::Entry& CadService::find_model(const std::string& spec) {
  if (spec.rfind("object:", 0) == 0) {
    const std::string id = spec.substr(7);
    if (const auto error = object_errors_.find(id); error != object_errors_.end()) {
      const auto tab = error->second.find('\t');
      throw RequestError{error->second.substr(0, tab), "the STEP model of object '" + id + "' could not be read: " +
                                                           error->second.substr(tab + 1)};
    }
    const auto it = objects_.find(id);
    if (it == objects_.end()) {
      throw RequestError{"CAD_UNKNOWN_MODEL", "the cell file names no STEP model for object '" + id + "'"};
    }
    return models_.at(it->second);
  }
  if (spec.rfind("sha256:", 0) == 0) {
    const auto it = models_.find(spec.substr(7));
    if (it == models_.end()) {
      throw RequestError{"CAD_UNKNOWN_MODEL", "no model with " + spec + " is loaded (load it first)"};
    }
    return it->second;
  }
  if (spec.empty()) {
    throw RequestError{"CAD_BAD_REQUEST", "model is empty: expected object:<id>, sha256:<hex> or a file path"};
  }
  return add(cad::read_step_file(readable(spec), settings_.limits), false);
}

fs::path CadService::readable(const std::string& spec) const {
  const fs::path path(spec);
  const bool allowed = path.is_absolute() && std::any_of(settings_.allowed_dirs.begin(), settings_.allowed_dirs.end(),
                                                         [&](const fs::path& dir) { return inside(path, dir); });
  if (!allowed) {
    throw RequestError{"CAD_FORBIDDEN_PATH", "the service may not read " + spec +
                                                 " (an absolute path inside an allowed folder is required)"};
  }
  return path;
}

// A node of a file (args_json.node) as a model of its own: extracted as STEP, read back like any file
// (its sha256 then names it), answered like a load with the node and, in data, its STEP bytes.
CadAnswer CadService::load_node(const CadQuery& query) {
  const json args = parse_args(query.args_json);
  const cad::NodePath path = node_arg(args.at("node"), settings_.limits.max_assembly_depth);
  cad::ExtractedNode node;
  std::string source = "content";
  if (!query.content.empty()) {
    node = cad::extract_step_node(query.content, source, path, settings_.limits);
  } else if (query.model.rfind("object:", 0) == 0) {
    const auto file = object_paths_.find(query.model.substr(7));
    if (file == object_paths_.end()) {
      throw RequestError{"CAD_UNKNOWN_MODEL", "the cell file names no STEP model for " + query.model};
    }
    source = file->second.string();
    node = cad::extract_step_node(file->second, path, settings_.limits);
  } else if (query.model.rfind("sha256:", 0) == 0 || query.model.empty()) {
    throw RequestError{"CAD_BAD_REQUEST", "a node is taken from a file: send its bytes in content, or name it by "
                                          "object:<id> or its path (not " + (query.model.empty() ? "nothing" : query.model) + ")"};
  } else {
    source = query.model;
    node = cad::extract_step_node(readable(query.model), path, settings_.limits);
  }
  Entry& entry = add(cad::read_step_bytes(node.step, source + " node " + cad::to_string(path), settings_.limits), false);
  CadAnswer answer;
  answer.model_sha256 = entry.model.sha256();
  json result = cad::features_json(entry.features, false);
  result["product"] = cad::to_json(entry.model.product());
  result["source"] = entry.model.source();
  result["node"] = {{"path", path}, {"name", node.name}, {"instance", node.instance},
                    {"pose_in_file", cad::to_json(node.pose_in_file)}};
  answer.result_json = result.dump();
  answer.data.assign(node.step.begin(), node.step.end());
  return answer;
}

CadAnswer CadService::answer(const CadQuery& query) {
  CadAnswer answer;
  try {
    if (query.kind == QueryKind::kLoad && parse_args(query.args_json).contains("node")) {
      answer = load_node(query);
      answer.ok = true;
      answer.code = "OK";
      return answer;
    }
    Entry* entry = nullptr;
    if (query.kind == QueryKind::kLoad && !query.content.empty()) {
      entry = &add(cad::read_step_bytes(query.content, "content", settings_.limits), false);
    } else {
      entry = &find_model(query.model);
    }
    answer.model_sha256 = entry->model.sha256();
    switch (query.kind) {
      case QueryKind::kLoad: {
        json result = cad::features_json(entry->features, false);
        result["product"] = cad::to_json(entry->model.product());
        result["source"] = entry->model.source();
        answer.result_json = result.dump();
        break;
      }
      case QueryKind::kFeatures: answer.result_json = cad::features_json(entry->features, true).dump(); break;
      case QueryKind::kTessellation:
        if (!entry->mesh) {
          entry->mesh = cad::tessellate(entry->model);
        }
        answer.data = entry->mesh->glb;
        answer.result_json = cad::tessellation_json(entry->features, *entry->mesh).dump();
        break;
      case QueryKind::kFrame: {
        CadAnswer framed = frame(*entry, query.args_json);
        answer.result_json = std::move(framed.result_json);
        break;
      }
      case QueryKind::kDerive: {
        CadAnswer derived = derive(*entry, query.args_json);
        answer.result_json = std::move(derived.result_json);
        break;
      }
    }
    answer.ok = true;
    answer.code = "OK";
  } catch (const RequestError& error) {
    answer.code = error.code;
    answer.message = error.message;
  } catch (const cad::CadError& error) {
    answer.code = std::string(cad::to_string(error.code()));
    answer.message = error.what();
  } catch (const std::exception& error) {
    answer.code = "CAD_INTERNAL";
    answer.message = std::string("unexpected error: ") + error.what();
  }
  return answer;
}

CadAnswer CadService::frame(Entry& entry, const std::string& args_json) const {
  const json args = parse_args(args_json);
  const std::string rule = args.value("rule", "");
  Eigen::Isometry3d pose;
  if (rule == "edges") {
    const auto edges = args.find("edges");
    if (edges == args.end() || !edges->is_array() || edges->size() != 2) {
      throw RequestError{"CAD_BAD_REQUEST", "rule \"edges\" needs args_json.edges: [E1, E2]"};
    }
    pose = cad::frame_from_edges(entry.features, point_arg(args, "point_m"),
                                 entity_arg(entry.features, (*edges)[0], cad::EntityKind::kEdge, "edges[0]"),
                                 entity_arg(entry.features, (*edges)[1], cad::EntityKind::kEdge, "edges[1]"));
  } else if (rule == "face") {
    if (!args.contains("face")) {
      throw RequestError{"CAD_BAD_REQUEST", "rule \"face\" needs args_json.face"};
    }
    pose = cad::frame_from_face(entry.model, entry.features,
                                entity_arg(entry.features, args["face"], cad::EntityKind::kFace, "face"),
                                point_arg(args, "point_m"));
  } else if (rule == "hole") {
    pose = cad::frame_from_hole(entry.features, int_arg(args, "hole"));
  } else if (rule == "above_centre_of_mass") {
    // A sling's ring: 20 mm above the part, over its centre of mass.
    pose = cad::frame_above_centre_of_mass(entry.model, kSlingClearanceM);
  } else {
    throw RequestError{"CAD_BAD_REQUEST", "args_json.rule must be \"edges\", \"face\", \"hole\" or "
                                          "\"above_centre_of_mass\", not \"" + rule + "\""};
  }
  CadAnswer answer;
  answer.result_json = json{{"rule", rule}, {"frame", cad::to_json(pose)}}.dump();
  return answer;
}

CadAnswer CadService::derive(Entry& entry, const std::string& args_json) const {
  const json args = parse_args(args_json);
  const std::string parameter = args.value("parameter", "");
  json result{{"parameter", parameter}};
  if (parameter == "screw_list") {
    // A frame at each hole's entry (z out of the hole), in the model's frame: every hole, or the picked
    // ones in the order picked. A hole is picked by its index or by a reference to one of its faces
    // (resolved: a stale reference is refused). Each screw carries the reference of the hole's first
    // face, which a planner keeps to find the hole again.
    std::vector<int> picked;
    const auto holes = args.find("holes");
    if (holes == args.end()) {
      for (const auto& hole : entry.features.holes) picked.push_back(hole.index);
    } else {
      if (!holes->is_array() || holes->empty() || holes->size() > 1000) {
        throw RequestError{"CAD_BAD_REQUEST", "args_json.holes must be a non-empty array (at most 1000) of hole indices or face references"};
      }
      for (std::size_t i = 0; i < holes->size(); ++i) {
        const json& h = (*holes)[i];
        const std::string what = "holes[" + std::to_string(i) + "]";
        if (h.is_number_integer()) {
          const int index = h.get<int>();
          if (index < 0 || index >= static_cast<int>(entry.features.holes.size())) {
            throw RequestError{"CAD_BAD_REFERENCE", what + ": no hole " + std::to_string(index) + " (the model has " +
                                                        std::to_string(entry.features.holes.size()) + ")"};
          }
          picked.push_back(index);
          continue;
        }
        const int face = entity_arg(entry.features, h, cad::EntityKind::kFace, what);
        const auto owner = std::find_if(entry.features.holes.begin(), entry.features.holes.end(), [face](const cad::Hole& hole) {
          return std::find(hole.faces.begin(), hole.faces.end(), face) != hole.faces.end();
        });
        if (owner == entry.features.holes.end()) {
          throw RequestError{"CAD_BAD_REFERENCE", what + ": face " + std::to_string(face) + " is not a face of a hole"};
        }
        picked.push_back(owner->index);
      }
    }
    result["screws"] = json::array();
    for (const int index : picked) {
      const cad::Hole& hole = entry.features.holes.at(static_cast<std::size_t>(index));
      result["screws"].push_back({{"hole", hole.index},
                                  {"ref", cad::to_json(entry.features.reference(cad::EntityKind::kFace, hole.faces.front()))},
                                  {"diameter_m", hole.diameter_m},
                                  {"depth_m", hole.depth_m},
                                  {"through", hole.through},
                                  {"pose", cad::to_json(cad::frame_from_hole(entry.features, hole.index))}});
    }
  } else if (parameter == "grasp_pose") {
    // The tool's z goes into the picked face: the face frame turned about its x axis.
    const int face = entity_arg(entry.features, args.value("face", json()), cad::EntityKind::kFace, "face");
    Eigen::Isometry3d pose = cad::frame_from_face(entry.model, entry.features, face, point_arg(args, "point_m"));
    pose.linear() = pose.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
    result["pose"] = cad::to_json(pose);
  } else if (parameter == "resolve") {
    // Where each reference lands on this model, as every rule resolves it (cad::resolve): its index, or
    // why it is stale. Asked once for every rule into a model that changed.
    const auto refs = args.find("references");
    if (refs == args.end() || !refs->is_array() || refs->size() > 10000) {
      throw RequestError{"CAD_BAD_REQUEST", "args_json.references must be an array (at most 10000) of reference objects"};
    }
    result["resolved"] = json::array();
    for (std::size_t i = 0; i < refs->size(); ++i) {
      const std::string what = "references[" + std::to_string(i) + "]";
      if (!(*refs)[i].is_object()) throw RequestError{"CAD_BAD_REQUEST", what + " must be a reference object"};
      cad::Reference ref;
      try {
        ref = cad::reference_from_json((*refs)[i]);
      } catch (const cad::CadError& error) {
        throw RequestError{"CAD_BAD_REFERENCE", what + ": " + error.what()};
      }
      try {
        result["resolved"].push_back({{"index", cad::resolve(entry.features, ref)}});
      } catch (const cad::StaleReference& error) {
        result["resolved"].push_back({{"stale", error.why()}});
      }
    }
  } else {
    throw RequestError{"CAD_BAD_REQUEST", "args_json.parameter must be \"screw_list\", \"grasp_pose\" or \"resolve\", not \"" +
                                              parameter + "\""};
  }
  CadAnswer answer;
  answer.result_json = result.dump();
  return answer;
}

}  // namespace rigger::cad_service
