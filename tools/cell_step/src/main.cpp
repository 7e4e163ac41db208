// rigger_cell_step [CELL_FILE [OUT_DIR]]: writes the simulated cell's load.step and target.step (and
// part.step, part_fixture.step when the cell has them).
// Defaults: the installation's cell file (rigger/base/install.hpp) and the models/ folder beside
// CELL_FILE. To regenerate the repository's models, from its root:
//   build/bin/rigger_cell_step deploy/cell/simulated_cell.json

#include "cell_parts.hpp"

#include <iostream>

#include "rigger/base/install.hpp"

int main(int argc, char** argv) {
  const std::filesystem::path cell_path =
      argc > 1 ? std::filesystem::path(argv[1]) : rigger::find_data_path(rigger::kDefaultCellFile).path;
  const std::filesystem::path out_dir = argc > 2 ? std::filesystem::path(argv[2]) : cell_path.parent_path() / "models";
  try {
    const auto parts = rigger::cad::cell_parts(rigger::cell::load_cell_file(cell_path));
    rigger::cad::write_cell_parts(parts, out_dir);
    for (const auto& part : parts) {
      std::cout << "wrote " << (out_dir / part.file_name).string() << " (" << part.holes.size() << " holes)\n";
    }
  } catch (const std::exception& error) {
    std::cerr << "rigger_cell_step: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
