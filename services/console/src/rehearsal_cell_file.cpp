#include "rehearsal_cell_file.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::console {

namespace fs = std::filesystem;

RehearsalCellFiles::RehearsalCellFiles(fs::path cell_folder, fs::path root)
    : cell_folder_(std::move(cell_folder)), root_(fs::absolute(root)), store_(root_ / "models") {}

RehearsalCellFiles::~RehearsalCellFiles() {
  std::error_code ignored;
  fs::remove_all(root_, ignored);
}

fs::path RehearsalCellFiles::write(const CellTarget& target) {
  const std::string name = "the cell's revision " + std::to_string(target.revision);
  if (target.sha256.empty())
    throw std::runtime_error("the cell's revision is unknown: no world model answers on the cell's domain");
  const fs::path dir = root_ / ("revision-" + std::to_string(target.revision) + "-" + target.sha256.substr(0, 16));
  const fs::path file = dir / "cell.json";
  std::error_code error;
  if (fs::is_regular_file(file, error)) return file;

  const cell::CellFile doc = cell::parse_cell_file(target.cell_json, name);
  // Stored by their own sha256: bytes that are not what the pin says stay unused, the pin names them missing.
  for (const auto& model : target.models)
    if (model.step.size() <= cell::kMaxModelBytes) store_.put(model.step);
  // Without a cell folder an unpinned model resolves nowhere: a folder that is certainly empty.
  const fs::path folder = cell_folder_.empty() ? root_ / "no-cell-folder" : cell_folder_;
  const cell::ModelFolder models = cell::resolve_models(doc, folder, store_, root_ / "model-folders");
  if (!models.missing.empty()) {
    const auto& m = models.missing.front();
    throw std::runtime_error(
        name + " at " + m.pointer + ": the model " + m.name + " (sha256 " + m.sha256 +
        ") is neither among the models the cell's world model published nor in " +
        (cell_folder_.empty() ? "a cell folder (rehearsal/cell_folder is not configured)" : cell_folder_.string()));
  }
  std::vector<std::pair<std::string, fs::path>> links;  // model path -> its bytes
  for (const cell::CellEntity& entity : doc.entities) {
    if (!entity.model || entity.model->step.empty()) continue;
    const fs::path source = models.dir / entity.model->step;
    if (!fs::is_regular_file(source, error)) {
      throw std::runtime_error(
          name + " at " + entity.pointer + "/model: the model " + entity.model->step + " is not in " +
          (cell_folder_.empty() ? "a cell folder (rehearsal/cell_folder is not configured)" : cell_folder_.string()));
    }
    links.emplace_back(entity.model->step, fs::canonical(source));
  }

  // Made beside its place and renamed: a start never sees half a folder.
  const fs::path temporary = dir.string() + ".tmp-" + std::to_string(::getpid());
  fs::remove_all(temporary, error);
  fs::create_directories(temporary, error);
  if (error)
    throw std::runtime_error(temporary.string() +
                             ": the rehearsal cell's folder could not be made: " + error.message());
  {
    std::ofstream out(temporary / "cell.json", std::ios::binary | std::ios::trunc);
    out.write(target.cell_json.data(), static_cast<std::streamsize>(target.cell_json.size()));
    out.close();
    if (!out) throw std::runtime_error((temporary / "cell.json").string() + ": could not be written");
  }
  for (const auto& [step, source] : links) {
    const fs::path link = temporary / fs::path(step).lexically_normal();
    if (fs::is_symlink(link, error)) continue;  // two objects on one model
    fs::create_directories(link.parent_path(), error);
    if (!error) fs::create_symlink(source, link, error);
    if (error)
      throw std::runtime_error(link.string() + ": the link to the model could not be made: " + error.message());
  }
  fs::rename(temporary, dir, error);
  if (error)
    throw std::runtime_error(dir.string() + ": the rehearsal cell's folder could not be made: " + error.message());
  return file;
}

}  // namespace rigger::console
