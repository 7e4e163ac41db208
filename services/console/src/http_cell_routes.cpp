// The console's cell revision routes: the running revision and the history (viewers), and a new revision
// (a cell document, or a rollback to an earlier revision) in two steps, programmers only: the first call
// has the world model check it without changing anything (a dry run) and answers what would change with
// a confirmation id; POST /api/confirm applies it. The world model's refusals keep their reason.
#include <httplib.h>

#include "http_api.hpp"
#include "http_replies.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::console {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
namespace cell_code = world_protocol::cell_code;

namespace {

// The world model's codes as HTTP: a revision that touches what a running task holds conflicts with the
// cell's state (409, as does one that changes nothing); a document that breaks a rule is unprocessable
// (422, the message naming file and JSON pointer).
int http_status(const std::string& code) {
  if (code == cell_code::kHeldByTask || code == cell_code::kUnchanged) return 409;
  if (code == cell_code::kInvalid) return 422;
  if (code == cell_code::kUnknownRevision) return 404;
  if (code == cell_code::kTooLarge) return 413;
  if (code == cell_code::kBadRequest) return 400;
  return 503;  // no world model answered
}

// The request a selected revision makes; the imported STEP files its document pins go with it (payload
// "models": [{"sha256", "name"}], the name as the document's model.step). Empty
// `missing` when every one of them is still kept, else the first one that is not.
world_protocol::CellRequest request_of(const json& payload, const std::string& who, bool dry_run,
                                       const ImportedModels& imports, std::string& missing) {
  world_protocol::CellRequest q;
  for (const json& wanted : payload.value("models", json::array())) {
    std::optional<world_protocol::CellModel> model = imports.find(wanted.value("sha256", ""));
    if (!model) {
      missing = wanted.value("sha256", "");
      break;
    }
    model->name = wanted.value("name", "");  // as the document names it, not as the file was called
    q.models.push_back(std::move(*model));
  }
  q.op = payload.at("op") == "rollback" ? world_protocol::CellOp::kRollback : world_protocol::CellOp::kApply;
  q.cell_json = payload.value("cell_json", "");
  q.revision = payload.value("revision", std::uint64_t{0});
  q.comment = payload.value("comment", "");
  q.who = who;
  q.dry_run = dry_run;
  return q;
}

/// What a revision changes (added, removed, moved, changed) from the world model's answer, whose result
/// holds it as "changes" beside the revision's number, sha256 and summary.
json changes_of(const json& answer) {
  if (!answer.is_object()) return json::object();
  const json result = answer.value("result", json::object());
  return result.is_object() ? result.value("changes", json::object()) : json::object();
}

}  // namespace

void HttpApi::imported_file_gone(const httplib::Request& req, httplib::Response& res, const std::string& sha256) {
  send_error(res, 409,
             "the imported STEP file sha256:" + sha256.substr(0, 12) +
                 "… is no longer kept by the console (it keeps the last " +
                 std::to_string(ImportedModels::kMaxImports) + " imports): import it again",
             req.path);
}

void HttpApi::send_cell_answer(const httplib::Request& req, httplib::Response& res, const ActionResult& r) {
  if (r.ok) return send_json(res, r.data.value("result", json::object()));
  const std::string code = r.data.is_object() ? r.data.value("code", "") : "";
  send_error(res, http_status(code), code.empty() ? r.message : code + ": " + r.message, req.path);
}

void HttpApi::get_cell(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  world_protocol::CellRequest q;
  q.op = world_protocol::CellOp::kShow;
  send_cell_answer(req, res, backend_.cell_request(q));
}

std::optional<HttpApi::RunningCell> HttpApi::running_cell(const httplib::Request& req, httplib::Response& res) {
  world_protocol::CellRequest show;
  show.op = world_protocol::CellOp::kShow;
  const auto running = backend_.cell_request(show);
  if (!running.ok) {
    send_cell_answer(req, res, running);
    return std::nullopt;
  }
  JsonParseResult parsed = parse_json_bounded(
      running.data.value("result", json::object()).value("cell_json", std::string("{}")), {16U * 1024U * 1024U, 64});
  if (!parsed.ok() || !parsed.value.is_object()) {
    send_error(res, 503, "the world model's running revision is not a JSON document", req.path);
    return std::nullopt;
  }
  return RunningCell{running.data.value("cell_revision", std::uint64_t{0}), std::move(parsed.value)};
}

void HttpApi::get_cell_history(const httplib::Request& req, httplib::Response& res) {
  if (!who(req, res, Role::kViewer)) return;
  world_protocol::CellRequest q;
  q.op = world_protocol::CellOp::kHistory;
  const auto r = backend_.cell_request(q);
  if (!r.ok) return send_cell_answer(req, res, r);
  json out = r.data.value("result", json::object());
  out["cell_revision"] = r.data.value("cell_revision", std::uint64_t{0});
  send_json(res, out);
}

void HttpApi::post_cell_revision(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  json payload = {{"comment", text_field(*b, "comment")}};
  std::string target;
  if (b->contains("cell") && (*b)["cell"].is_object()) {
    payload["op"] = "apply";
    payload["cell_json"] = to_text((*b)["cell"]);
    target = "apply";
  } else if (b->contains("rollback") && (*b)["rollback"].is_number_unsigned()) {
    payload["op"] = "rollback";
    payload["revision"] = (*b)["rollback"];
    target = "rollback " + std::to_string((*b)["rollback"].get<std::uint64_t>());
  } else {
    return send_error(res, 400, "expected {\"cell\": {<a cell document>}} or {\"rollback\": <revision number>}",
                      req.path);
  }
  select_cell_revision(*user, payload, target, req, res);
}

void HttpApi::select_cell_revision(const User& user, const json& payload, const std::string& target,
                                   const httplib::Request& req, httplib::Response& res, json extra) {
  // The dry run: refused now, with the world model's reason, rather than after the confirmation.
  std::string missing;
  const world_protocol::CellRequest request = request_of(payload, "console:" + user.name, true, imports_, missing);
  if (!missing.empty()) return imported_file_gone(req, res, missing);
  const auto check = backend_.cell_request(request);
  if (!check.ok) {
    audit(user, "select cell " + target, "cell", "refused: " + check.message);
    return send_cell_answer(req, res, check);
  }
  const std::string id =
      new_confirmation({user.name, "cell", target, to_text(payload), Clock::now() + config_.confirm_timeout});
  audit(user, "select cell " + target, "cell", "awaiting confirmation " + id);
  json answer = {{"confirmation_id", id},
                 {"action", "cell " + target},
                 {"cell_revision", check.data.value("cell_revision", std::uint64_t{0})},
                 {"changes", changes_of(check.data)},
                 {"expires_in_s", std::chrono::duration<double>(config_.confirm_timeout).count()}};
  if (extra.is_object()) answer.update(extra);
  send_json(res, answer, 202);
}

void HttpApi::confirm_cell(const User& user, const Pending& p, const httplib::Request& req, httplib::Response& res) {
  std::string missing;
  const world_protocol::CellRequest request =
      request_of(json::parse(p.payload), "console:" + user.name, false, imports_, missing);
  if (!missing.empty()) return imported_file_gone(req, res, missing);
  const auto r = backend_.cell_request(request);
  const std::uint64_t revision = r.data.is_object() ? r.data.value("cell_revision", std::uint64_t{0}) : 0;
  audit(user, "cell " + p.task_id, "cell", r.ok ? "revision " + std::to_string(revision) : "refused: " + r.message);
  if (!r.ok) return send_cell_answer(req, res, r);
  send_json(res, {{"done", "cell " + p.task_id}, {"cell_revision", revision}, {"changes", changes_of(r.data)}});
}

}  // namespace rigger::console
