#pragma once
/// @file
/// The rehearsal cell started on the cell's revision (docs/console.md, "The rehearsal cell on demand"):
/// the revision's document written byte for byte as `cell.json` in a folder of its own, with a link at
/// each of its model paths to the model's bytes — a pinned model from the models the cell's world model
/// published (the console keeps them), an unpinned one from the rehearsal cell's own cell folder. The
/// start command gets that file as RIGGER_CELL_FILE; its world model and cell_sim start on it (--cell),
/// so the simulator builds the revision's objects, the crane's load among them, from the start.
///
/// Pure C++ over the cell file loader and its model store; no DDS. Not thread-safe (the console's loop).
#include <filesystem>

#include "rehearsal_revision.hpp"
#include "rigger/cell_config/cell_models.hpp"

namespace rigger::console {

class RehearsalCellFiles {
 public:
  /// `cell_folder`: where the rehearsal cell reads the models a revision does not pin (empty: unknown);
  /// `root`: a folder of this object's own, made on the first write() and removed with it.
  RehearsalCellFiles(std::filesystem::path cell_folder, std::filesystem::path root);
  ~RehearsalCellFiles();
  RehearsalCellFiles(const RehearsalCellFiles&) = delete;
  RehearsalCellFiles& operator=(const RehearsalCellFiles&) = delete;

  /// The absolute path of `target`'s cell file, written (once per revision and sha256) with its models.
  /// @throws std::runtime_error saying why it cannot be: the revision unknown, its document not a cell
  /// file, a model at its pointer found neither among the published ones nor in the cell folder, or a
  /// file that could not be written.
  std::filesystem::path write(const CellTarget& target);

 private:
  std::filesystem::path cell_folder_;
  std::filesystem::path root_;
  cell::ModelStore store_;
};

}  // namespace rigger::console
