#include "rigger/cell_config/cell_models.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "rigger/base/sha256.hpp"

namespace rigger::cell {
namespace {

namespace fs = std::filesystem;

bool leaves_folder(const fs::path& relative) {
  if (relative.is_absolute()) return true;
  const fs::path normal = relative.lexically_normal();
  return normal.empty() || *normal.begin() == "..";
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

// A name unique to this process and call, for temporary files and folders beside their final place.
std::string temporary_suffix() {
  static unsigned counter = 0;
  return ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(++counter);
}

}  // namespace

std::string model_name_problem(std::string_view name) {
  if (name.empty()) return "expected a model file name, got an empty one";
  if (name.size() > 255) return "expected at most 255 bytes, got " + std::to_string(name.size());
  if (name.find('\0') != std::string_view::npos) return "expected a file name without NUL bytes";
  const fs::path path{std::string(name)};
  if (leaves_folder(path) || std::string(name).find("..") != std::string::npos)
    return "expected a path inside the cell folder, without \"..\", got \"" + std::string(name) + "\"";
  const std::string extension = lower(path.extension().string());
  if (extension != ".step" && extension != ".stp")
    return "expected a .step or .stp file, got \"" + std::string(name) + "\"";
  return {};
}

ModelStore::ModelStore(fs::path dir) : dir_(std::move(dir)) {}

fs::path ModelStore::find(const std::string& sha256) const {
  if (dir_.empty() || !is_sha256_hex(sha256)) return {};
  fs::path path = dir_ / (sha256 + ".step");
  std::error_code error;
  return fs::is_regular_file(path, error) ? path : fs::path();
}

std::string ModelStore::put(std::string_view bytes) {
  if (bytes.size() > kMaxModelBytes) {
    throw std::runtime_error("a STEP model of " + std::to_string(bytes.size()) + " bytes: expected at most " +
                             std::to_string(kMaxModelBytes));
  }
  const std::string sha256 = sha256_hex(bytes);
  if (!find(sha256).empty()) return sha256;
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error) throw std::runtime_error(dir_.string() + ": the model store could not be made: " + error.message());
  const fs::path final_path = dir_ / (sha256 + ".step");
  const fs::path temporary = dir_ / (sha256 + temporary_suffix());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      fs::remove(temporary, error);
      throw std::runtime_error(temporary.string() + ": the model could not be written");
    }
  }
  fs::rename(temporary, final_path, error);
  if (error) {
    fs::remove(temporary, error);
    throw std::runtime_error(final_path.string() + ": the model could not be stored: " + error.message());
  }
  return sha256;
}

std::string file_sha256(const fs::path& path) {
  std::error_code error;
  const auto size = fs::file_size(path, error);
  if (error || size > kMaxModelBytes) return {};
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return sha256_hex(bytes);
}

ModelFolder resolve_models(const CellFile& file, const fs::path& cell_folder, const ModelStore& store,
                           const fs::path& links_root) {
  ModelFolder folder;
  folder.dir = cell_folder;
  std::vector<std::pair<std::string, fs::path>> links;  // model path -> the file it reads
  bool from_store = false;
  for (const CellEntity& entity : file.entities) {
    if (!entity.model || entity.model->step.empty()) continue;
    const ObjectModel& model = *entity.model;
    fs::path local = cell_folder / model.step;
    if (!model.step_sha256.empty()) {
      std::error_code error;
      const bool here = fs::is_regular_file(local, error) && file_sha256(local) == model.step_sha256;
      if (!here) {
        local = leaves_folder(model.step) ? fs::path() : store.find(model.step_sha256);
        if (local.empty()) {
          folder.missing.push_back({entity.pointer + "/model", model.step, model.step_sha256});
          continue;
        }
        from_store = true;
      }
    }
    links.emplace_back(model.step, fs::absolute(local));
  }
  if (!from_store) return folder;

  std::string key;
  for (const auto& [name, target] : links) key += name + '\t' + target.string() + '\n';
  folder.dir = links_root / sha256_hex(key).substr(0, 32);
  std::error_code error;
  if (fs::is_directory(folder.dir, error)) return folder;
  const fs::path temporary = folder.dir.string() + temporary_suffix();
  fs::create_directories(temporary, error);
  if (error) throw std::runtime_error(temporary.string() + ": the folder of models could not be made: " + error.message());
  for (const auto& [name, target] : links) {
    if (leaves_folder(name)) {
      fs::remove_all(temporary, error);
      throw std::runtime_error("model \"" + name + "\" lies outside the cell folder: it cannot be read beside a " +
                               "model received with the revision; put it in the cell folder");
    }
    const fs::path link = temporary / fs::path(name).lexically_normal();
    fs::create_directories(link.parent_path(), error);
    if (!error) fs::create_symlink(target, link, error);
    if (error) {
      const std::string why = error.message();
      fs::remove_all(temporary, error);
      throw std::runtime_error(link.string() + ": the link to the model could not be made: " + why);
    }
  }
  fs::rename(temporary, folder.dir, error);
  if (error) {  // made meanwhile by another reader of the same revision: theirs is the same
    fs::remove_all(temporary, error);
    if (!fs::is_directory(folder.dir, error))
      throw std::runtime_error(folder.dir.string() + ": the folder of models could not be made");
  }
  return folder;
}

}  // namespace rigger::cell
