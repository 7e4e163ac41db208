#include "cell_parts.hpp"

#include <stdexcept>

namespace rigger::cad {
namespace {

Eigen::Vector3d box_size(const cell::CellFile& cell, const std::string& id) {
  const cell::CellEntity* entity = cell.find(id);
  if (entity == nullptr || !entity->model || entity->model->shape != "box") {
    throw std::runtime_error(cell.source + ": no object '" + id + "' with a box model");
  }
  return entity->model->size_m;
}

}  // namespace

std::vector<CellPart> cell_parts(const cell::CellFile& cell) {
  const Eigen::Vector3d load = box_size(cell, "load");
  const Eigen::Vector3d target = box_size(cell, "target");
  std::vector<CellPart> out{CellPart{"load", "load.step", parts::cell_load(load), parts::cell_load_holes(load)},
                            CellPart{"target", "target.step", parts::cell_target(target), parts::cell_target_holes()}};
  // The small part Pick and Place move, about its centre, and the table it sits on, below its top-face
  // frame: plain boxes (optional: a cell without them has only the crane's objects).
  if (cell.find("part") != nullptr) {
    const Eigen::Vector3d part = box_size(cell, "part");
    out.push_back(CellPart{"part", "part.step", parts::drilled_box(-part / 2, part / 2, {}), {}});
  }
  if (cell.find("part_fixture") != nullptr) {
    const Eigen::Vector3d table = box_size(cell, "part_fixture");
    const Eigen::Vector3d half(table.x() / 2, table.y() / 2, 0.0);
    out.push_back(CellPart{"part_fixture",
                           "part_fixture.step",
                           parts::drilled_box(-half - Eigen::Vector3d(0, 0, table.z()), half, {}),
                           {}});
  }
  return out;
}

void write_cell_parts(const std::vector<CellPart>& parts, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  for (const auto& part : parts) {
    write_step(part.shape_m, part.object, dir / part.file_name);
  }
}

}  // namespace rigger::cad
