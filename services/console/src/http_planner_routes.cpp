// The console's planner routes (validation, screws and frames from CAD picks) and the rehearsal cell's:
// the simulated cell on a domain of its own, where a recipe runs first.
#include <atomic>
#include <cctype>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

// Eigen before httplib.h, whose system headers define names Eigen uses.
#include "model_replacement.hpp"
#include "placement.hpp"
#include "planner_declare_frames.hpp"

#include <httplib.h>

#include "http_api.hpp"
#include "http_replies.hpp"
#include "planner_declare.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

/// The CAD service did not answer a planner request: a refusal of the picks (a CAD_ code: stale, not a
/// hole, not perpendicular, off the face) is the request's fault (400, at `picks` in the body); no
/// answer is the cell's (503).
void send_cad_refusal(httplib::Response& res, const httplib::Request& req, const std::string& message,
                      const std::string& picks) {
  const bool refused = message.rfind("CAD_", 0) == 0;
  send_error(res, refused ? 400 : 503, "the CAD service: " + message, req.path + (refused ? picks : ""));
}

void no_rehearsal(const httplib::Request& req, httplib::Response& res) {
  send_error(res, 409,
             "no rehearsal domain is configured: set rehearsal_domain in the console's configuration and run the "
             "simulated cell on that domain (docs/console.md, \"Rehearsal\")",
             req.path);
}

/// What the Planner is answered for a file it read (an import, or a node of one): the CAD service's
/// result without its name for the bytes it was sent (not a file anyone can open), with the file's name,
/// size and model id.
json imported_answer(const ActionResult& loaded, const std::string& name, std::size_t bytes) {
  const std::string sha = loaded.data.value("model_sha256", "");
  json out = loaded.data.value("result", json::object());
  out.erase("source");
  out["name"] = name;
  out["bytes"] = bytes;
  out["model"] = "sha256:" + sha;
  out["model_sha256"] = sha;
  return out;
}

}  // namespace

// Validation by the controller's own validator against the live library; the answer is 200 either way
// (ok and errors by JSON pointer), 400 only for a body that is not a recipe at all.
void HttpApi::post_planner_validate(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kProgrammer)) return;
  send_json(res, validate_recipe(skills_.library(), req.body));
}

// The screw list of picked holes: derived by the CAD service, matched to the world model's screw holes.
void HttpApi::post_planner_screws(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kProgrammer)) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const ScrewRequest request = parse_screw_request(*b);
    const auto derived =
        backend_.cad("derive", request.model, json{{"parameter", "screw_list"}, {"holes", request.holes}}.dump());
    if (!derived.ok) return send_cad_refusal(res, req, derived.message, "#/holes");
    const auto entity = backend_.world_entity(request.entity);
    if (!entity.ok) return send_error(res, 503, "the world model: " + entity.message, req.path);
    send_json(res, screws_with_features(request, derived.data.value("model_sha256", ""),
                                        derived.data.value("result", json::object()), entity.data));
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// A pose parameter from picks: the CAD service's frame rule, as a pose in the part's frame.
void HttpApi::post_planner_frame(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kProgrammer)) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const FrameRequest request = parse_frame_request(*b);
    const auto framed = backend_.cad("frame", request.model, request.args.dump());
    if (!framed.ok) return send_cad_refusal(res, req, framed.message, "");
    const json result = framed.data.value("result", json::object());
    send_json(res, {{"model", request.model}, {"model_sha256", framed.data.value("model_sha256", "")},
                    {"args", request.args}, {"frame", result.value("frame", json())},
                    {"pose", pose_from_cad_frame(result, request.entity)}});
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// An object placed by picks: a face of it on a face of another object (both frames from the CAD service's
// face rule), its new pose written into the running cell document, and that document as a revision in
// two steps (the world model's dry run now, POST /api/confirm applies it).
void HttpApi::post_planner_place(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const PlaceRequest request = parse_place_request(*b);
    const auto own = backend_.cad("frame", request.own.model, request.own.args.dump());
    if (!own.ok) return send_cad_refusal(res, req, own.message, "");
    const auto onto = backend_.cad("frame", request.onto.model, request.onto.args.dump());
    if (!onto.ok) return send_cad_refusal(res, req, onto.message, "#/onto");
    const auto running = running_cell(req, res);
    if (!running) return;
    const json& cell = running->document;
    const Eigen::Isometry3d own_face = frame_from_cad(own.data.value("result", json::object()));
    const Eigen::Isometry3d onto_face = frame_from_cad(onto.data.value("result", json::object()));
    double turn_deg = request.turn_deg;
    std::optional<Eigen::Vector3d> onto_edge;
    if (request.own_edge && request.onto_edge) {
      // The edges' directions, from the CAD service's features of each model.
      const auto direction = [&](const FrameRequest& at, int edge, const std::string& pointer) {
        const auto features = backend_.cad("features", at.model, "{}");
        if (!features.ok) throw PlannerError{pointer, features.message};
        const json edges = features.data.value("result", json::object()).value("edges", json::array());
        if (edge >= static_cast<int>(edges.size()))
          throw PlannerError{pointer, at.model + " has " + std::to_string(edges.size()) + " edges, no edge " + std::to_string(edge)};
        const json sig = edges[static_cast<std::size_t>(edge)].value("signature", json::object());
        if (sig.value("type", "") != "line")
          throw PlannerError{pointer, "edge " + std::to_string(edge) + " is a " + sig.value("type", "?") + ", not a straight edge"};
        const json d = sig.at("direction");
        return Eigen::Vector3d(d[0].get<double>(), d[1].get<double>(), d[2].get<double>());
      };
      const Eigen::Vector3d own_dir = direction(request.own, *request.own_edge, "/edge");
      onto_edge = direction(request.onto, *request.onto_edge, "/onto/edge");
      turn_deg += edge_turn_deg(onto_face, *onto_edge, own_face, own_dir);
    }
    const Eigen::Isometry3d support_T_object =
        placed_on(offset_along(onto_face, onto_edge, request.offset_m), own_face, turn_deg);
    const json placed =
        cell_with_placement(cell, request.own.entity, request.onto.entity, support_T_object, request.localized);
    json pose = position_rpy(support_T_object);
    pose["frame"] = request.onto.entity;
    const std::string comment = request.comment.empty()
                                    ? "place " + request.own.entity + " on " + request.onto.entity
                                    : request.comment;
    const json payload = {{"op", "apply"}, {"cell_json", to_text(placed)}, {"comment", comment}};
    select_cell_revision(*user, payload, "place " + request.own.entity, req, res,
                         {{"pose_on_support", pose}, {"object", request.own.entity}, {"support", request.onto.entity}});
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// A STEP file to import, sent as the body (any content type): read by the CAD service (its bounded reader,
// in a child process), answered with what the Planner shows before the part enters the cell: its model
// id (sha256:<hex>, for the features and the tessellation), units, product tree, counts and holes. A file
// the CAD service refuses (not STEP, no length unit, no solid, too large) is the request's fault: 400 with
// its code and reason. Nothing changes in the cell.
void HttpApi::post_planner_import(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  // ?model=<sha256>: one of the cell's own models (GET /api/planner/cell_models), e.g. for a second
  // object of a part the cell holds already; else the body is the STEP file the person chose.
  std::string step;
  std::string name = req.has_param("name") ? req.get_param_value("name") : "upload.step";
  if (req.has_param("model")) {
    if (!req.body.empty())
      return send_error(res, 400, "send either a model of the cell (model=) or a file's bytes, not both", req.path);
    const ActionResult kept = backend_.cell_models(req.get_param_value("model"));
    if (!kept.ok) return send_error(res, 404, kept.message, req.path + "#model");
    step = kept.data.at("step").get<std::string>();
    const std::string path = kept.data.at("name").get<std::string>();
    name = path.substr(path.find_last_of('/') + 1);
  } else {
    step = req.body;
  }
  if (name.empty() || name.size() > 255 || name.find_first_of("/\\") != std::string::npos)
    return send_error(res, 400, "name: expected the file's name (1 to 255 characters, no folder)", req.path + "#name");
  if (step.empty()) return send_error(res, 400, "the body is empty: send the STEP file's bytes", req.path);
  const std::size_t size = step.size();
  const auto loaded = backend_.cad_load(name, step, "{}");
  if (!loaded.ok) {
    audit(*user, "import STEP", name, "refused: " + loaded.message);
    return send_cad_refusal(res, req, loaded.message, "");
  }
  const std::string sha = loaded.data.value("model_sha256", "");
  audit(*user, "import STEP", name, "read as sha256:" + sha);
  imports_.keep(sha, name, std::move(step));
  send_json(res, imported_answer(loaded, name, size));
}

// A node of an imported file's product tree (a part or a sub-assembly, by its path from the root) as a file
// of its own: the CAD service extracts it as STEP (its own frame, names and unit kept, the same bytes for
// the same node) and reads it back; the console keeps those bytes like an imported file's, so Add makes
// the node alone an object. Answered like an import, with the node ({"path", "name", "instance",
// "pose_in_file"}) and the file it came from ({"model", "name"}). A node that does not exist or holds no
// solid is the request's fault (400 at #/node with the CAD service's reason).
void HttpApi::post_planner_import_node(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const NodeRequest request = parse_node_request(*b);
    auto file = imports_.find(request.sha256);
    if (!file) return imported_file_gone(req, res, request.sha256);
    imports_.touch(request.sha256);  // the file stays while its nodes are chosen
    const std::string path = json(request.node).dump();
    const auto loaded = backend_.cad_load(file->name, std::move(file->step), json{{"node", request.node}}.dump());
    if (!loaded.ok) {
      audit(*user, "import STEP node", file->name + " " + path, "refused: " + loaded.message);
      return send_cad_refusal(res, req, loaded.message, "#/node");
    }
    const std::string sha = loaded.data.value("model_sha256", "");
    const json node = loaded.data.value("result", json::object()).value("node", json::object());
    std::string name;
    for (const char c : node.value("name", std::string())) name += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    name = (name.empty() ? "node" : name.substr(0, 64)) + ".step";
    std::string step = loaded.data.value("data", std::string());
    const std::size_t size = step.size();
    audit(*user, "import STEP node", file->name + " " + path, "read as sha256:" + sha);
    imports_.keep(sha, name, std::move(step));
    json out = imported_answer(loaded, name, size);
    out["file"] = {{"model", "sha256:" + request.sha256}, {"name", file->name}};
    send_json(res, out);
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// The models of the cell's running revision, to import one of them again as a new object.
void HttpApi::get_planner_cell_models(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kProgrammer)) return;
  const ActionResult list = backend_.cell_models("");
  if (!list.ok) return send_error(res, 503, list.message, req.path);
  send_json(res, list.data);
}

// An imported STEP file made a cell object: named, of a material (or fixed), standing on the floor beside
// the cell, its model pinned by sha256 and sent with the revision (the world model keeps it and publishes
// it to every service). The revision goes to the world model as a dry run, confirmed by POST /api/confirm;
// Place then puts the object where it belongs.
void HttpApi::post_planner_add(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const AddRequest request = parse_add_request(*b);
    if (!imports_.find(request.sha256)) return imported_file_gone(req, res, request.sha256);
    // A new object is built into the simulator's running physics: not while a task moves the cell.
    if (refused_while_tasks_run(*user, "add " + request.id, "add the part", req, res)) return;
    const auto features = backend_.cad("features", "sha256:" + request.sha256, "{}");
    if (!features.ok) return send_cad_refusal(res, req, features.message, "#/model");
    const double lowest_z = lowest_vertex_z(features.data.value("result", json::object()));
    const auto running = running_cell(req, res);
    if (!running) return;
    const json added = cell_with_new_object(running->document, request, lowest_z);
    const std::string comment = request.comment.empty() ? "add " + request.id + " (imported)" : request.comment;
    const json payload = {
        {"op", "apply"}, {"cell_json", to_text(added)}, {"comment", comment},
        {"models", json::array({{{"sha256", request.sha256}, {"name", imported_model_name(request.id)}}})}};
    select_cell_revision(*user, payload, "add " + request.id, req, res,
                         {{"object", request.id}, {"material", request.material}});
  } catch (const PlannerError& e) {
    send_error(res, e.pointer == "/id" ? 409 : 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// A task moving the cell refuses a revision that rebuilds its physics (`what`: the audit's target, `doing`:
// what the person does, for the message): true when refused (answered 409).
bool HttpApi::refused_while_tasks_run(const User& user, const std::string& what, const std::string& doing,
                                      const httplib::Request& req, httplib::Response& res) {
  const std::size_t running = state_.running_tasks();
  if (running == 0) return false;
  audit(user, "select cell " + what, "cell", "refused: a task runs");
  send_error(res, 409,
             std::to_string(running) + " task" + (running == 1 ? " runs" : "s run") + " on the cell: " + doing +
                 " once " + (running == 1 ? "it has" : "they have") + " ended; nothing was changed",
             req.path);
  return true;
}

// A new version of an object's model: the imported file replaces it, pinned by its sha256, with the CAD
// rules that no longer resolve on it dropped and named in the answer (declared again by picks).
void HttpApi::post_planner_replace(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const ReplaceRequest request = parse_replace_request(*b);
    if (!imports_.find(request.sha256)) return imported_file_gone(req, res, request.sha256);
    if (refused_while_tasks_run(*user, "replace the model of " + request.object, "replace the model", req, res)) return;
    const auto running = running_cell(req, res);
    if (!running) return;
    // Every rule's references resolved on the new model at once, as the world model will resolve them.
    struct CadRefusal {
      std::string message;
    };
    const Resolver resolve = [&](const std::vector<json>& refs) {
      std::vector<std::string> why;
      if (refs.empty()) return why;
      const auto answer = backend_.cad("derive", "sha256:" + request.sha256,
                                       json{{"parameter", "resolve"}, {"references", refs}}.dump());
      if (!answer.ok) throw CadRefusal{answer.message};
      for (const json& r : answer.data.value("result", json::object()).value("resolved", json::array()))
        why.push_back(r.value("stale", ""));
      return why;
    };
    std::optional<Replacement> replaced;
    try {
      replaced = cell_with_replaced_model(running->document, request, resolve);
    } catch (const CadRefusal& e) {
      return send_cad_refusal(res, req, e.message, "#/model");
    }
    const Replacement& r = *replaced;
    const std::string comment = request.comment.empty() ? "a new model of " + request.object : request.comment;
    const json payload = {{"op", "apply"}, {"cell_json", to_text(r.cell)}, {"comment", comment},
                          {"models", json::array({{{"sha256", request.sha256},
                                                   {"name", replaced_model_name(request.object, request.sha256)}}})}};
    json dropped = json::array();
    for (const DroppedFeature& d : r.dropped) dropped.push_back({{"feature", d.feature}, {"why", d.why}});
    select_cell_revision(*user, payload, "replace the model of " + request.object, req, res,
                         {{"object", request.object}, {"kept", r.kept}, {"dropped", dropped}});
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  }
}

// A feature declared by picks: the rule built here from the CAD service's references, added to the running
// revision's document, which goes to the world model as a revision dry run (confirmed by POST /api/confirm).
void HttpApi::post_planner_declare(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  try {
    const DeclareRequest request = parse_declare_request(*b);
    const auto running = running_cell(req, res);
    if (!running) return;
    const json& cell = running->document;
    json declared;
    if (request.kind == "rope_attachment" || request.kind == "marker") {
      const auto frame = backend_.cad("frame", request.model, frame_args(request).dump());
      const char* picked = request.picks.contains("hole")                   ? "#/hole"
                           : request.picks.contains("above_centre_of_mass") ? "#/above_centre_of_mass"
                                                                            : "#/face";
      if (!frame.ok) return send_cad_refusal(res, req, frame.message, picked);
      const Eigen::Isometry3d at = frame_from_cad(frame.data.value("result", json::object()));
      if (request.kind == "marker") {
        // The whole square on the face: each corner is a point of it.
        for (const Eigen::Vector3d& corner : marker_corners(request, at)) {
          const json args = {{"rule", "face"}, {"face", request.picks["face"]}, {"point_m", {corner.x(), corner.y(), corner.z()}}};
          const auto on_face = backend_.cad("frame", request.model, args.dump());
          if (!on_face.ok)
            throw PlannerError{"/size_m", "a marker of " + std::to_string(std::lround(request.picks.value("size_m", 0.0) * 1000)) +
                                              " mm does not fit on face " + request.picks["face"].dump() +
                                              " at that point: a corner is off the face (" + on_face.message + ")"};
        }
      }
      // The crane carries one load: a part taking the rope hangs where the load hung, the load set down
      // where the part stood (cell_with_load_exchanged); both models' vertices give their lowest points.
      const std::string holder = request.kind == "rope_attachment" ? rope_holder(cell, request.entity) : "";
      json exchanged;
      if (!holder.empty()) {
        const auto own = backend_.cad("features", request.model, "{}");
        if (!own.ok) return send_cad_refusal(res, req, own.message, "#/model");
        const auto held = backend_.cad("features", "object:" + holder, "{}");
        if (!held.ok) return send_cad_refusal(res, req, "the crane's load " + holder + ": " + held.message, "#/model");
        exchanged = cell_with_load_exchanged(cell, request.entity, at.translation(), own.data.value("result", json::object()),
                                             holder, held.data.value("result", json::object()));
      }
      declared = declare_at_frame(request, holder.empty() ? cell : exchanged, at);
      if (request.kind == "marker") {
        const std::string note = marker_view_note(declared["cell"], request.entity, request.picks.value("marker_id", 0), at);
        if (!note.empty()) declared["note"] = note;
      }
    } else {
      const auto features = backend_.cad("features", request.model, "{}");
      if (!features.ok) return send_cad_refusal(res, req, features.message, "#/model");
      json target_features = json::object();
      if (!request.target.empty()) {
        const auto target = backend_.cad("features", "object:" + request.target, "{}");
        if (!target.ok) return send_cad_refusal(res, req, target.message, "#/target/model");
        target_features = target.data.value("result", json::object());
      }
      declared = declare_feature(request, cell, features.data.value("result", json::object()), target_features);
    }
    const std::string what = "declare " + request.kind + " " + request.entity + "/" + request.name;
    const json payload = {{"op", "apply"}, {"cell_json", to_text(declared["cell"])}, {"comment", what}};
    json extra = {{"features", declared["features"]}, {"rule", declared["rule"]}, {"base_revision", running->revision}};
    if (declared.contains("rope_from")) extra["rope_from"] = declared["rope_from"];
    if (declared.contains("note")) extra["note"] = declared["note"];
    select_cell_revision(*user, payload, "apply (" + what + ")", req, res, extra);
  } catch (const PlannerError& e) {
    send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
  } catch (const json::exception& e) {
    send_error(res, 503, std::string("the CAD service's features are not of the expected form: ") + e.what(), req.path);
  }
}

// Its state and stream are /api/state's and /api/events' of that domain, kept apart from the cell's.
void HttpApi::get_rehearsal_state(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  if (!rehearsal_) return no_rehearsal(req, res);
  json snapshot = rehearsal_->state.snapshot(req.has_param("task") ? req.get_param_value("task") : "");
  snapshot["domain"] = rehearsal_->domain_id;
  send_json(res, snapshot);
}

void HttpApi::get_rehearsal_events(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer, true)) return;
  if (!rehearsal_) return no_rehearsal(req, res);
  // A page watching the rehearsal keeps a started rehearsal cell from its idle stop.
  std::atomic<int>& watchers = rehearsal_->watchers;
  ++watchers;
  std::shared_ptr<void> watching(nullptr, [&watchers](void*) { --watchers; });
  stream_events(rehearsal_->events, req, res, rehearsal_->events.last_seq(), streams_, std::move(watching));
}

// The rehearsal cell the console starts on demand: its phase, and why its last start failed.
void HttpApi::get_rehearsal_cell(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  if (!rehearsal_) return no_rehearsal(req, res);
  const auto r = backend_.rehearsal_cell();
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, r.data);
}

// Nothing real moves in a rehearsal, so it is one step (no confirmation), but journaled like a publish.
void HttpApi::post_planner_rehearse(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  if (!rehearsal_) {
    audit(*user, "rehearse", "", "refused: no rehearsal domain configured");
    return no_rehearsal(req, res);
  }
  auto recipe = body(req, res);
  if (!recipe) return;
  const std::string task_id = text_field(*recipe, "task_id");
  if (task_id.empty())
    return send_error(res, 400, "the recipe needs a non-empty string task_id", req.path + "#/task_id");
  const std::string domain = std::to_string(rehearsal_->domain_id);
  const auto refuse = [&](int status, const std::string& why, json errors = json::array()) {
    audit(*user, "rehearse", task_id, "refused: " + why);
    json answer = {{"error", why}, {"where", req.path}, {"domain", rehearsal_->domain_id}};
    if (!errors.empty()) answer["errors"] = std::move(errors);
    send_json(res, answer, status);
  };
  if (!rehearsal_->state.task(task_id).is_null())
    return refuse(409, "task " + task_id + " already ran on the rehearsal domain " + domain +
                           " and a controller takes a task id once: rehearse under a new task id");
  // The rehearsal controller's own verdict (its validator, against the library its executors announce).
  const auto r = backend_.rehearse(task_id, req.body, "console:" + user->name);
  if (r.data.is_object() && r.data.value("starting", false)) {
    // No controller yet: the cell is being started; the page follows /api/rehearsal/cell and sends again.
    const json cell = r.data.value("cell", json::object());
    // Restarting: its simulator refused the cell's revision live, it starts again on the revision's document.
    const bool restarting = r.data.value("restarting", false);
    audit(*user, "rehearse", task_id,
          "held: " +
              std::string(restarting                         ? "restarting"
                          : r.data.value("started", false) ? "started"
                                                           : "starting") +
              " the rehearsal cell of domain " + domain + " (log " + cell.value("log", "") + "); nothing was sent" +
              (restarting ? ": " + r.message : ""));
    return send_json(res,
                     {{"starting", true}, {"restarting", restarting}, {"task_id", task_id},
                      {"domain", rehearsal_->domain_id}, {"cell", cell}, {"why", restarting ? r.message : ""}},
                     202);
  }
  const bool rejected = r.data.is_object() && r.data.value("state", "") == "REJECTED";
  if (rejected) return refuse(409, r.message, r.data.value("errors", json::array()));
  // The rehearsal cell is not on the cell's running revision (its world model refused it, is not there,
  // or did not report it in time): not rehearsed on a cell other than the real one.
  if (r.data.is_object() && r.data.value("cell_refused", false)) return refuse(409, r.message);
  if (!r.ok) return refuse(503, r.message);
  audit(*user, "rehearse", task_id, "sent to rehearsal domain " + domain);
  send_json(res, {{"done", "rehearse"}, {"task_id", task_id}, {"domain", rehearsal_->domain_id},
                  {"state", r.data.value("state", "")}});
}

}  // namespace rigger::console
