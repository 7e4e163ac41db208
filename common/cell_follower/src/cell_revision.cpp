#include "rigger/cell_follower/cell_revision.hpp"

#include <system_error>

#include "rigger/base/bounded_json.hpp"

namespace rigger::cell_follower {
namespace {

RevisionReading refuse(std::uint64_t revision, const std::string& why) {
  RevisionReading r;
  r.refusal = "cell revision " + std::to_string(revision) + ": " + why;
  return r;
}

}  // namespace

RevisionReading read_revision(const world_protocol::CellRevision& sent, const std::filesystem::path& cell_file,
                              const ReceivedModels& received) {
  if (sent.cell_revision == 0) return refuse(0, "expected a revision number >= 1");
  FollowedRevision taken;
  taken.revision = sent.cell_revision;
  taken.previous_revision = sent.previous_revision;
  taken.model_dir = cell::cell_model_folder(cell_file);
  taken.sha256 = sent.sha256;
  taken.who = sent.who;
  taken.comment = sent.comment;
  taken.stamp = sent.stamp;
  try {
    taken.cell = cell::parse_cell_file(sent.cell_json, cell_file.string());
    taken.document = nlohmann::json::parse(sent.cell_json);  // bounded and valid: parse_cell_file read it
  } catch (const std::exception& error) {
    return refuse(sent.cell_revision, error.what());
  }
  // A pinned model comes from the cell folder when it holds those bytes, else from the received ones.
  try {
    const cell::ModelStore none{{}};
    cell::ModelFolder folder = cell::resolve_models(taken.cell, taken.model_dir,
                                                    received.store != nullptr ? *received.store : none,
                                                    received.links_root);
    if (!folder.missing.empty()) {
      RevisionReading waiting;
      waiting.missing = std::move(folder.missing);
      waiting.refusal = "cell revision " + std::to_string(sent.cell_revision) + ": " + cell_file.string() + ": " +
                        waiting.missing.front().pointer + "/sha256: expected the STEP model \"" +
                        waiting.missing.front().name + "\" with sha256 " + waiting.missing.front().sha256 +
                        " in this reader's cell folder or on rigger/world/cell_model, got neither";
      return waiting;
    }
    taken.model_dir = std::move(folder.dir);
  } catch (const std::exception& error) {
    return refuse(sent.cell_revision, error.what());
  }
  // An unpinned model travels with the cell folder, not on the wire: one this reader's folder lacks is named.
  for (const cell::CellEntity& entity : taken.cell.entities) {
    if (!entity.model || entity.model->step.empty() || !entity.model->step_sha256.empty()) continue;
    const std::filesystem::path path = taken.model_dir / entity.model->step;
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) {
      return refuse(sent.cell_revision, cell_file.string() + ": " + entity.pointer +
                                            "/model/step: expected the STEP model " + path.string() +
                                            " in this reader's cell folder, got no such file");
    }
  }
  if (!sent.changes_json.empty()) {
    JsonParseResult parsed = parse_json_bounded(sent.changes_json, {4U * 1024U * 1024U, 16});
    if (!parsed.ok() || !parsed.value.is_object()) {
      return refuse(sent.cell_revision, "changes_json: expected a JSON object" +
                                            (parsed.ok() ? std::string() : ", got " + parsed.error->to_string()));
    }
    taken.changes = std::move(parsed.value);
  }
  RevisionReading r;
  r.revision = std::move(taken);
  return r;
}

}  // namespace rigger::cell_follower
