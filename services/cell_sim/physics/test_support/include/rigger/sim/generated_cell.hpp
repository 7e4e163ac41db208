#pragma once
/// @file
/// A cell the repository does not ship, for tests and benchmarks: a folder with a cell file (the shared
/// demo cell's devices and camera) and STEP models written with OpenCascade: a fixture table, an
/// L-shaped 25 kg bracket on the crane's rope (two solids), a flange plate with six holes as the static
/// target, and three loose parts on the table (a STEP block, a STEP roller, a box shorthand).

#include <cstddef>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "rigger/sim/cell_geometry.hpp"

namespace rigger::sim {

class GeneratedCell {
 public:
  /// The table's top face, world z (m).
  static constexpr double kTableTopZ = 0.70;

  /// Writes the STEP models into a new folder under /tmp and builds the cell file in memory from
  /// `shared_cell_json`'s devices (default: the repository's deploy/cell/simulated_cell.json).
  /// @throws std::runtime_error when a model cannot be made or written.
  GeneratedCell();
  explicit GeneratedCell(const std::filesystem::path& shared_cell_json);
  /// Removes the folder.
  ~GeneratedCell();
  GeneratedCell(const GeneratedCell&) = delete;
  GeneratedCell& operator=(const GeneratedCell&) = delete;

  /// The cell file, to change before write() or load().
  nlohmann::json& document() { return cell_; }
  const nlohmann::json& document() const { return cell_; }
  const std::filesystem::path& dir() const { return dir_; }
  /// The entity index of `id` in the cell file. @throws std::out_of_range
  std::size_t index_of(const std::string& id) const;
  /// Writes the cell file as dir()/cell.json and returns its path.
  std::filesystem::path write() const;
  /// write(), then the physics' reading of it. @throws CellGeometryError
  CellGeometry load() const;
  /// The CellGeometryError load() throws, or "" when it loads.
  std::string error() const;

 private:
  std::filesystem::path dir_;
  nlohmann::json cell_;
};

}  // namespace rigger::sim
