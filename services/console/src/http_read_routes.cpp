// The console's read routes: who am I, the cell's state and event streams, plots, the journal, the world
// model, the CAD model and the skills.
#include <cstdlib>

#include <httplib.h>

#include "http_api.hpp"
#include "http_replies.hpp"

namespace rigger::console {

using nlohmann::json;

void HttpApi::get_me(const httplib::Request& req, httplib::Response& res) {
  if (auto u = who(req, res, Role::kViewer)) send_json(res, {{"user", u->name}, {"role", role_name(u->role)}});
}

void HttpApi::get_state(const httplib::Request& req, httplib::Response& res) {
  if (who(req, res, Role::kViewer)) send_json(res, state_.snapshot(req.has_param("task") ? req.get_param_value("task") : ""));
}

void HttpApi::get_events(const httplib::Request& req, httplib::Response& res) {
  if (who(req, res, Role::kViewer, true)) stream_events(events_, req, res, events_.last_seq(), streams_);
}

void HttpApi::get_plots_stream(const httplib::Request& req, httplib::Response& res) {
  if (who(req, res, Role::kViewer, true)) stream_events(plots_, req, res, plots_.last_seq(), streams_);
}

void HttpApi::get_plots(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  double from = 0, to = 1e300;
  try {
    if (req.has_param("from")) from = std::stod(req.get_param_value("from"));
    if (req.has_param("to")) to = std::stod(req.get_param_value("to"));
  } catch (const std::exception&) {
    return send_error(res, 400, "from and to are times in seconds since the epoch", req.path);
  }
  std::string out = "[";
  bool first = true;
  for (const auto& e : plots_.retained()) {
    const double t = plot_row_time(e.data);
    if (t < from || t > to) continue;
    if (!first) out += ",";
    out += e.data;
    first = false;
  }
  out += "]";
  res.set_content(out, kJson);
}

void HttpApi::get_runs(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  if (runs_ == nullptr) return send_error(res, 404, "this console keeps no runs (its runs_dir is empty)", req.path);
  send_json(res, {{"runs", runs_->runs()}});
}

void HttpApi::get_run_plots(const httplib::Request& req, httplib::Response& res) {
  send_run_rows(req, res, &RunArchive::rows);
}

void HttpApi::get_run_cell(const httplib::Request& req, httplib::Response& res) {
  send_run_rows(req, res, &RunArchive::cell_rows);
}

void HttpApi::send_run_rows(const httplib::Request& req, httplib::Response& res,
                            std::optional<std::string> (RunArchive::*read)(const std::string&) const) {
  if (!who(req, res, Role::kViewer)) return;
  const std::string task = req.matches[1];
  const auto rows = runs_ != nullptr ? (runs_->*read)(task) : std::nullopt;
  if (!rows) return send_error(res, 404, "no run of task '" + task + "' is kept", req.path);
  res.set_content(*rows, kJson);
}

void HttpApi::get_journal(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  const std::string task = req.has_param("task") ? req.get_param_value("task") : "";
  const auto r = backend_.journal(task);
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, {{"task_id", task}, {"entries", r.data}});
}

void HttpApi::get_world_entity(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  const auto r = backend_.world_entity(req.matches[1]);
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, r.data);
}

void HttpApi::get_world_entities(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  const auto r = backend_.world_list();
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, {{"entities", r.data}});
}

void HttpApi::get_cad_model(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  const std::string model = req.has_param("model") ? req.get_param_value("model") : "object:target";
  const auto r = backend_.cad("tessellation", model, "{}");
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  res.set_content(r.data.at("data").get_ref<const std::string&>(), "model/gltf-binary");
}

// The planner's reads: the model's features (holes, faces with signatures) and which GLB primitive is
// which face (the tessellation's "parts").
void HttpApi::cad_read(const httplib::Request& req, httplib::Response& res, const char* kind, const char* what) {
  if (!who(req, res, Role::kViewer)) return;
  const std::string model = req.has_param("model") ? req.get_param_value("model") : "object:target";
  const auto r = backend_.cad(kind, model, "{}");
  if (!r.ok) return send_error(res, 503, std::string("the ") + what + " of " + model + ": " + r.message, req.path);
  json out = r.data.value("result", json::object());
  out["model"] = model;
  send_json(res, out);
}

void HttpApi::get_cad_features(const httplib::Request& req, httplib::Response& res) {
  cad_read(req, res, "features", "features");
}

void HttpApi::get_cad_parts(const httplib::Request& req, httplib::Response& res) {
  cad_read(req, res, "tessellation", "tessellation parts");
}

void HttpApi::get_skills(const httplib::Request& req, httplib::Response& res) {
  if (who(req, res, Role::kViewer)) send_json(res, skills_.to_json());
}

}  // namespace rigger::console
