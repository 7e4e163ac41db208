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
  return {CellPart{"load", "load.step", parts::cell_load(load), parts::cell_load_holes(load)},
          CellPart{"target", "target.step", parts::cell_target(target), parts::cell_target_holes()}};
}

void write_cell_parts(const std::vector<CellPart>& parts, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  for (const auto& part : parts) {
    write_step(part.shape_m, part.object, dir / part.file_name);
  }
}

}  // namespace rigger::cad
