#include "cell_keeper.hpp"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <utility>

#include "rigger/base/bounded_json.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/cell_config/cell_diff.hpp"
#include "step_model_bounds.hpp"
#include "world_json.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using world_protocol::CellOp;
namespace code = world_protocol::cell_code;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cell::CellFileError(path.string(), "", "a readable file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.size() > cell::kMaxCellFileBytes) {
    throw cell::CellFileError(path.string(), "", "at most " + std::to_string(cell::kMaxCellFileBytes) + " bytes",
                              "a larger file");
  }
  return text;
}

// Where the uploaded models live: beside the history, or, with the history in memory, in a folder of this
// process's own.
fs::path model_root(const fs::path& history_folder) {
  if (!history_folder.empty()) return history_folder;
  return fs::temp_directory_path() / ("rigger-world-models-" + std::to_string(::getpid()));
}

// The history and the replies are JSON: text that is not UTF-8 cannot go into them.
bool utf8(const std::string& text) {
  try {
    (void)json(text).dump();
    return true;
  } catch (const json::type_error&) {
    return false;
  }
}

json everything_added(const cell::CellFile& cell) {
  json added = json::array();
  for (const auto& e : cell.entities) added.push_back(e.id);
  return {{"added", added}, {"removed", json::array()}, {"moved", json::array()}, {"changed", json::array()}};
}

json summary_of(const CellRevisionRecord& r) {
  return {{"cell_revision", r.revision},
          {"previous_revision", r.previous_revision},
          {"sha256", r.sha256},
          {"who", r.who},
          {"comment", r.comment},
          {"stamp_ns", to_unix_ns(r.stamp)},
          {"summary", cell::summarize_changes(r.changes)},
          {"changes", r.changes}};
}

// Whether a request from `client_id` comes from the skill executor `executor`: its runs' clients are
// "<executor id>-<pid>" (skill_sdk's executor node). Such a revision may change what that executor's own runs
// hold: the controller lets one run at a time hold a resource, so it is the run that proposes it (a calibration
// writing the camera it claims).
bool from_executor(const std::string& client_id, const std::string& executor) {
  const std::size_t dash = client_id.rfind('-');
  if (dash == std::string::npos || dash + 1 == client_id.size()) return false;
  if (client_id.find_first_not_of("0123456789", dash + 1) != std::string::npos) return false;
  return client_id.compare(0, dash, executor) == 0 && dash == executor.size();
}

}  // namespace

CellKeeper::CellKeeper(Settings settings, Stamp now)
    : settings_(std::move(settings)),
      cell_file_(fs::absolute(settings_.cell_file).lexically_normal().string()),
      models_(model_root(settings_.history_folder) / "models"),
      links_root_(model_root(settings_.history_folder) / "model-folders"),
      history_(settings_.history_folder, settings_.max_revisions) {
  const std::string file_text = read_text(settings_.cell_file);
  const std::string file_sha256 = cad::sha256_hex(file_text);
  const CellRevisionRecord* latest = history_.latest_of(cell_file_);
  if (latest != nullptr && latest->file_sha256 == file_sha256) {
    running_ = validated(latest->cell_json, now);
    running_.record = *latest;
    running_doc_ = json::parse(latest->cell_json);
    return;
  }
  CellRevisionRecord record;
  RunningCell checked = validated(file_text, now);
  cell::CellFile& cell = checked.cell;
  json doc = json::parse(file_text);
  record.revision = history_.next_revision();
  record.cell_json = file_text;
  record.sha256 = file_sha256;
  record.cell_file = cell_file_;
  record.file_sha256 = file_sha256;
  record.who = "file";
  record.stamp = now;
  if (latest != nullptr) {
    // The file was edited since the world model last ran on it: the edit is a revision on top.
    record.previous_revision = latest->revision;
    record.comment = "the cell file changed on disk";
    const cell::CellFile before = cell::parse_cell_file(latest->cell_json, settings_.cell_file.string());
    record.changes = cell::diff_cells(before, json::parse(latest->cell_json), cell, doc);
  } else {
    record.comment = "the cell file";
    record.changes = everything_added(cell);
  }
  const std::string error = history_.append(record);
  if (!error.empty()) throw CellHistoryError("the first cell revision was not saved: " + error);
  checked.record = std::move(record);
  running_ = std::move(checked);
  running_doc_ = std::move(doc);
  started_new_ = true;
}

RunningCell CellKeeper::validated(const std::string& text, Stamp now) const {
  RunningCell checked;
  checked.cell = cell::parse_cell_file(text, settings_.cell_file.string());
  const cell::ModelFolder models = cell::resolve_models(
      checked.cell, cell::cell_model_folder(settings_.cell_file), models_, links_root_);
  if (!models.missing.empty()) {
    const cell::MissingModel& m = models.missing.front();
    throw cell::CellFileError(settings_.cell_file.string(), m.pointer + "/sha256",
                              "the STEP model \"" + m.name + "\" with these bytes in the cell folder or sent with "
                              "the request (riggerctl cell apply --with-models)",
                              "neither: sha256 " + m.sha256);
  }
  checked.model_dir = models.dir;
  const cell::CadDerivation cad = cell::derive_cad_features(checked.cell, checked.model_dir);
  describe_step_models(checked.cell, cad.read_models, checked.model_dir);
  WorldStore::from_config(checked.cell, now);
  return checked;
}

std::string CellKeeper::store_models(const world_protocol::CellRequest& request, const json& doc,
                                     std::vector<std::string>& added) {
  if (request.models.size() > cell::kMaxModelsPerRequest) {
    return "models: expected at most " + std::to_string(cell::kMaxModelsPerRequest) + ", got " +
           std::to_string(request.models.size());
  }
  // What the document pins: model.step -> model.sha256.
  std::map<std::string, std::string> pinned;
  for (const json& entity : doc.value("entities", json::array())) {
    const json model = entity.is_object() ? entity.value("model", json::object()) : json::object();
    if (model.is_object() && model.contains("step") && model.contains("sha256") && model["step"].is_string() &&
        model["sha256"].is_string())
      pinned[model["step"].get<std::string>()] = model["sha256"].get<std::string>();
  }
  for (std::size_t i = 0; i < request.models.size(); ++i) {
    const world_protocol::CellModel& m = request.models[i];
    const std::string where = "models/" + std::to_string(i) + " (\"" + m.name.substr(0, 255) + "\")";
    if (const std::string problem = cell::model_name_problem(m.name); !problem.empty()) return where + ": " + problem;
    if (m.step.size() > cell::kMaxModelBytes) {
      return where + ": expected at most " + std::to_string(cell::kMaxModelBytes) + " bytes, got " +
             std::to_string(m.step.size());
    }
    const std::string sha256 = sha256_hex(m.step);
    if (!m.sha256.empty() && m.sha256 != sha256)
      return where + ": its sha256 says " + m.sha256 + ", its bytes are " + sha256;
    const auto pin = pinned.find(m.name);
    if (pin == pinned.end() || pin->second != sha256) {
      return where + ": expected an object of the document whose model has step \"" + m.name + "\" and sha256 " +
             sha256 + ", found " + (pin == pinned.end() ? "none" : "sha256 " + pin->second);
    }
    const bool known = !models_.find(sha256).empty();
    try {
      models_.put(m.step);
    } catch (const std::exception& e) {
      return where + ": " + e.what();
    }
    if (!known) added.push_back(sha256);
  }
  return {};
}

std::vector<world_protocol::CellModel> CellKeeper::pinned_models(std::vector<std::string>* problems,
                                                              const std::set<std::string>& published) const {
  std::vector<world_protocol::CellModel> out;
  std::set<std::string> seen;
  for (const cell::CellEntity& entity : running_.cell.entities) {
    if (!entity.model || entity.model->step_sha256.empty() || !seen.insert(entity.model->step_sha256).second) continue;
    if (published.count(entity.model->step_sha256) != 0) {
      out.push_back({entity.model->step_sha256, entity.model->step, {}});
      continue;
    }
    const fs::path path = running_.model_dir / entity.model->step;
    std::ifstream in(path, std::ios::binary);
    std::string bytes;
    if (in) bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!in || sha256_hex(bytes) != entity.model->step_sha256) {
      if (problems != nullptr) problems->push_back(path.string() + ": no longer holds the pinned bytes");
      continue;
    }
    out.push_back({entity.model->step_sha256, entity.model->step, std::move(bytes)});
  }
  return out;
}

world_protocol::CellReply CellKeeper::reply(bool ok, const char* c, std::string message, json result) const {
  world_protocol::CellReply r;
  r.ok = ok;
  r.code = c;
  r.message = std::move(message);
  r.cell_revision = running_.record.revision;
  r.result_json = result.is_null() ? std::string() : result.dump();
  return r;
}

CellOutcome CellKeeper::handle(const world_protocol::CellRequest& request, const std::vector<HeldResource>& held,
                               Stamp now) {
  if (request.client_id.empty()) return {reply(false, code::kBadRequest, "client_id: expected a non-empty id"), {}};
  if (!request.op) {
    return {reply(false, code::kBadRequest,
                  "op: expected CELL_APPLY, CELL_ROLLBACK, CELL_SHOW or CELL_HISTORY, got " +
                      std::to_string(request.wire_op)),
            {}};
  }
  if (request.cell_json.size() > cell::kMaxCellFileBytes) {
    return {reply(false, code::kTooLarge,
                  "cell_json: expected at most " + std::to_string(cell::kMaxCellFileBytes) + " bytes, got " +
                      std::to_string(request.cell_json.size())),
            {}};
  }
  if (request.who.size() > kMaxCellWhoBytes || request.comment.size() > kMaxCellCommentBytes) {
    return {reply(false, code::kTooLarge,
                  "who, comment: expected at most " + std::to_string(kMaxCellWhoBytes) + " and " +
                      std::to_string(kMaxCellCommentBytes) + " bytes"),
            {}};
  }
  if (!utf8(request.who) || !utf8(request.comment))
    return {reply(false, code::kBadRequest, "who, comment: expected UTF-8 text"), {}};
  switch (*request.op) {
    case CellOp::kApply:
      if (request.cell_json.empty())
        return {reply(false, code::kBadRequest, "cell_json: expected a cell document"), {}};
      return propose(request.cell_json, request, held, now);
    case CellOp::kRollback: {
      const CellRevisionRecord* old = history_.find(request.revision);
      if (old == nullptr) {
        return {reply(false, code::kUnknownRevision,
                      "revision " + std::to_string(request.revision) +
                          ": expected one of the history (riggerctl cell "
                          "history)"),
                {}};
      }
      const std::string text = old->cell_json;  // propose() may append to the history
      return propose(text, request, held, now);
    }
    case CellOp::kShow:
      return show(request.revision == 0 ? running_.record.revision : request.revision);
    case CellOp::kHistory:
      return list();
  }
  return {reply(false, code::kBadRequest, "op: unknown"), {}};
}

CellOutcome CellKeeper::propose(const std::string& text, const world_protocol::CellRequest& request,
                                const std::vector<HeldResource>& held, Stamp now) {
  // Models new to the store leave it again unless this request makes the revision that pins them.
  std::vector<std::string> added;
  struct Forget {
    const cell::ModelStore& store;
    std::vector<std::string>& shas;
    bool keep = false;
    ~Forget() {
      std::error_code error;
      if (!keep)
        for (const std::string& sha : shas) fs::remove(store.find(sha), error);
    }
  } forget{models_, added};
  RunningCell checked;
  try {
    if (!request.models.empty()) {
      const JsonParseResult parsed = parse_json_bounded(text, {cell::kMaxCellFileBytes, cell::kMaxCellFileDepth});
      const std::string refused = store_models(request, parsed.ok() ? parsed.value : json(), added);
      if (!refused.empty()) return {reply(false, code::kInvalid, refused), {}};
    }
    checked = validated(text, now);
  } catch (const std::exception& e) {
    return {reply(false, code::kInvalid, e.what()), {}};
  }
  cell::CellFile& cell = checked.cell;
  const json doc = json::parse(text);
  const json changes = cell::diff_cells(running_.cell, running_doc_, cell, doc);
  if (cell::no_changes(changes) && doc == running_doc_) {
    return {reply(false, code::kUnchanged,
                  "the document equals the running revision " + std::to_string(running_.record.revision) + "'s"),
            {}};
  }
  const std::set<std::string> touched = cell::touched_entities(changes);
  for (const HeldResource& h : held) {
    if (touched.count(h.resource) == 0 || from_executor(request.client_id, h.executor)) continue;
    return {reply(false, code::kHeldByTask,
                  "\"" + h.resource + "\" is held by task " + h.task + " node " + h.node + " (skill " + h.skill +
                      " on " + h.executor + "): a revision may not move, remove or change it while the run lasts",
                  {{"entity", h.resource}, {"task", h.task}, {"node", h.node}, {"changes", changes}}),
            {}};
  }
  CellRevisionRecord record;
  record.revision = history_.next_revision();
  record.previous_revision = running_.record.revision;
  record.cell_json = text;
  record.sha256 = cad::sha256_hex(text);
  record.cell_file = cell_file_;
  record.file_sha256 = running_.record.file_sha256;  // the file itself has not changed since the start
  record.changes = changes;
  record.who = request.who;
  record.comment = request.op == CellOp::kRollback && request.comment.empty()
                       ? "rollback to revision " + std::to_string(request.revision)
                       : request.comment;
  record.stamp = now;
  json result = {{"cell_revision", record.revision},
                 {"previous_revision", record.previous_revision},
                 {"sha256", record.sha256},
                 {"summary", cell::summarize_changes(changes)},
                 {"changes", changes},
                 {"dry_run", request.dry_run}};
  if (request.dry_run) {
    result["cell_revision"] = nullptr;
    return {reply(true, code::kAccepted, "dry run: would be revision " + std::to_string(record.revision), result), {}};
  }
  const std::string error = history_.append(record);
  if (!error.empty()) return {reply(false, kCellNotSaved, "the revision was not saved: " + error), {}};
  forget.keep = true;
  checked.record = std::move(record);
  running_ = std::move(checked);
  running_doc_ = doc;
  CellOutcome outcome{reply(true, code::kAccepted, "revision " + std::to_string(running_.record.revision), result),
                      running_};
  return outcome;
}

CellOutcome CellKeeper::show(std::uint64_t revision) const {
  const CellRevisionRecord* r = history_.find(revision);
  if (r == nullptr) {
    return {reply(false, code::kUnknownRevision, "revision " + std::to_string(revision) + ": not in the history"), {}};
  }
  json result = summary_of(*r);
  result["cell_json"] = r->cell_json;
  return {reply(true, code::kAccepted, "revision " + std::to_string(revision), result), {}};
}

CellOutcome CellKeeper::list() const {
  json revisions = json::array();
  for (const CellRevisionRecord& r : history_.revisions()) revisions.push_back(summary_of(r));
  return {reply(true, code::kAccepted, std::to_string(revisions.size()) + " revisions",
                {{"running", running_.record.revision}, {"revisions", revisions}}),
          {}};
}

}  // namespace rigger::world
