#include "cell_keeper.hpp"

#include <fstream>
#include <iterator>
#include <utility>

#include "rigger/cad/model.hpp"
#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/cell_config/cell_diff.hpp"
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

// What the start goes through: the rules, the CAD derivation from the configured folder's models, the store.
cell::CellFile validated(const std::string& text, const fs::path& cell_file, Stamp now) {
  cell::CellFile cell = cell::parse_cell_file(text, cell_file.string());
  cell::derive_cad_features(cell, cell::cell_model_folder(cell_file));
  WorldStore::from_config(cell, now);
  return cell;
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

}  // namespace

CellKeeper::CellKeeper(Settings settings, Stamp now)
    : settings_(std::move(settings)),
      cell_file_(fs::absolute(settings_.cell_file).lexically_normal().string()),
      history_(settings_.history_folder, settings_.max_revisions) {
  const std::string file_text = read_text(settings_.cell_file);
  const std::string file_sha256 = cad::sha256_hex(file_text);
  const CellRevisionRecord* latest = history_.latest_of(cell_file_);
  if (latest != nullptr && latest->file_sha256 == file_sha256) {
    running_ = {*latest, validated(latest->cell_json, settings_.cell_file, now)};
    running_doc_ = json::parse(latest->cell_json);
    return;
  }
  CellRevisionRecord record;
  cell::CellFile cell = validated(file_text, settings_.cell_file, now);
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
  running_ = {std::move(record), std::move(cell)};
  running_doc_ = std::move(doc);
  started_new_ = true;
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
  cell::CellFile cell;
  try {
    cell = validated(text, settings_.cell_file, now);
  } catch (const std::exception& e) {
    return {reply(false, code::kInvalid, e.what()), {}};
  }
  const json doc = json::parse(text);
  const json changes = cell::diff_cells(running_.cell, running_doc_, cell, doc);
  if (cell::no_changes(changes) && doc == running_doc_) {
    return {reply(false, code::kUnchanged,
                  "the document equals the running revision " + std::to_string(running_.record.revision) + "'s"),
            {}};
  }
  const std::set<std::string> touched = cell::touched_entities(changes);
  for (const HeldResource& h : held) {
    if (touched.count(h.resource) == 0) continue;
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
  running_ = {std::move(record), std::move(cell)};
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
