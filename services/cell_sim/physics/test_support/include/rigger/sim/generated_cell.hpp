#pragma once
/// @file
/// A cell the repository does not ship, for tests and benchmarks, described only by a cell file and STEP models written
/// with OpenCascade: a fixture table, an L-shaped 25 kg bracket of two solids on the crane's rope (the load), a flange
/// plate with six through holes on the table (the target) and three loose parts on the table. The devices (crane,
/// robot, gripper, camera) are the shipped cell's; the objects stand where the shipped cell's load and target stand, in
/// the robot's reach and the camera's view.
///
/// Every feature a skill needs is a CAD rule over the generated models, with references found by
/// classifying the written STEP files (as `riggerctl cad inspect` shows them to an integrator):
/// bracket/grasp_web and bracket/pre_grasp (`face` rule on the web's outer face), the bracket's insertion
/// on the flange (`mate_faces`: the base plate's bottom on the flange's top), flange/h1..h6 (`hole`).
/// The rope attachment and the ArUco markers (bracket: 1, 2 on the web; flange: 10, 11 on a lug on its rim,
/// facing the camera) are numbers, as on any cell file.

#include <cstddef>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "rigger/sim/cell_geometry.hpp"

namespace rigger::sim {

class GeneratedCell {
 public:
  /// World z of the fixture table's top face, metres.
  static constexpr double kTableTopZ = 0.91;

  /// Writes the STEP models into a new folder under /tmp (removed with this object) and builds the cell
  /// document from the devices of `shared_cell_json` (default: the repository's
  /// deploy/cell/simulated_cell.json) and the generated objects. Throws std::runtime_error (or
  /// cad::CadError) when a model cannot be written or a referenced face is not found.
  GeneratedCell();
  explicit GeneratedCell(const std::filesystem::path& shared_cell_json);
  /// The same into `dir`/models (created), which stays: a test's log folder.
  GeneratedCell(std::filesystem::path dir, const std::filesystem::path& shared_cell_json);
  ~GeneratedCell();
  GeneratedCell(const GeneratedCell&) = delete;
  GeneratedCell& operator=(const GeneratedCell&) = delete;

  /// The cell document; tests may edit it before write().
  nlohmann::json& document() { return cell_; }
  const nlohmann::json& document() const { return cell_; }
  const std::filesystem::path& dir() const { return dir_; }

  /// Writes the document to dir()/cell.json (STEP paths in it are relative to that folder); its path.
  std::filesystem::path write() const;

  /// The position of `id` in /entities; throws std::out_of_range for an unknown id.
  std::size_t index_of(const std::string& id) const;
  /// write(), then the physics' reading of it. @throws CellGeometryError
  CellGeometry load() const;
  /// The CellGeometryError load() throws, or "" when it loads.
  std::string error() const;

  /// The scenario's recipe (`demo_recipe`: recipes/crane_insert.json) for this cell: its object and
  /// feature names replaced by the generated cell's (load → bracket, target → flange, the grasp and
  /// approach features, the flange's six holes), no coordinate in it. task_id becomes `task_id`.
  nlohmann::json recipe(const nlohmann::json& demo_recipe, const std::string& task_id) const;

 private:
  void build(const std::filesystem::path& shared_cell_json);

  std::filesystem::path dir_;
  bool remove_dir_ = false;
  nlohmann::json cell_;
};

/// A new product the repository does not ship, written with OpenCascade (the Planner's "your own product"):
/// an L bracket (the generated cell's, 0.40 x 0.30 m base plate and 0.30 m web) with two 18 mm through holes
/// in its base plate, and a base plate 0.50 x 0.34 x 0.03 m (x from -0.20 to 0.30), frame on its top face, with
/// six through holes of two diameters on a pattern that is not a rectangle (four of 17.5 mm on a trapezoid, two
/// of 14 mm) and a marker tab 0.02 x 0.24 x 0.12 m standing at its +x end (a second solid). The STEP files carry their units (metres) and nothing else: no feature is declared for them.
struct NewProductModels {
  std::filesystem::path bracket;  ///< bracket.step
  std::filesystem::path plate;    ///< base_plate.step
};
/// Writes both models into `dir` (created). Throws std::runtime_error (or cad::CadError) when one cannot be
/// written.
NewProductModels write_new_product(const std::filesystem::path& dir);

}  // namespace rigger::sim
