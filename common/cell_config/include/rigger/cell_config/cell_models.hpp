#pragma once
/// @file
/// Where a cell revision's STEP models are read from. A model is named by its path relative to the cell
/// folder (model.step) and, when pinned, by the sha256 of its bytes (model.sha256). A pinned model whose
/// bytes the reader's cell folder lacks — a part uploaded with a revision from a laptop or the Planner —
/// comes from a content-addressed store instead: the world model keeps the models uploaded to it there,
/// and a follower the ones it received on rigger/world/cell_model. resolve_models() makes one folder
/// where every model path of the revision resolves to the right bytes, so the readers (the CAD
/// derivation, the physics, the CAD service) keep reading `model_dir / model.step`.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell {

/// At most this many bytes per STEP model carried over DDS or stored (the console's import bound too).
inline constexpr std::size_t kMaxModelBytes = 64U * 1024U * 1024U;
/// At most this many models in one revision request.
inline constexpr std::size_t kMaxModelsPerRequest = 16;

/// Empty when `name` may name an uploaded model (model.step): a relative path of at most 255 bytes,
/// without "..", ending in .step or .stp (any case); else what is wrong with it.
std::string model_name_problem(std::string_view name);

/// STEP files by the sha256 of their bytes, one file `<sha256>.step` each in a folder. Writes are atomic
/// (a temporary file renamed), so a reader never sees half a model. Not thread-safe.
class ModelStore {
 public:
  explicit ModelStore(std::filesystem::path dir);
  /// The stored file of `sha256`, or an empty path when none.
  std::filesystem::path find(const std::string& sha256) const;
  /// Stores `bytes` (at most kMaxModelBytes) and returns their sha256. @throws std::runtime_error saying
  /// which file could not be written and why.
  std::string put(std::string_view bytes);
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

/// A pinned model found neither in the cell folder nor in the store.
struct MissingModel {
  std::string pointer;  ///< the object's model, e.g. "/entities/7/model"
  std::string name;     ///< model.step
  std::string sha256;   ///< model.sha256
};

/// Where to read the revision's models from.
struct ModelFolder {
  /// Pass as model_dir: the cell folder itself when it holds every model as pinned, else a folder of
  /// links under `links_root`, one per model path (to the cell folder's file or to the store's).
  std::filesystem::path dir;
  std::vector<MissingModel> missing;  ///< empty when every model resolves
};

/// Resolves every model of `file`: an unpinned one from `cell_folder`; a pinned one from `cell_folder`
/// when the bytes there have its sha256, else from `store`. A model path that leaves its folder ("..")
/// resolves only from the cell folder. @throws std::runtime_error when the folder of links cannot be made.
ModelFolder resolve_models(const CellFile& file, const std::filesystem::path& cell_folder, const ModelStore& store,
                           const std::filesystem::path& links_root);

/// The sha256 of the file at `path` (at most kMaxModelBytes read), or "" when it cannot be read.
std::string file_sha256(const std::filesystem::path& path);

}  // namespace rigger::cell
