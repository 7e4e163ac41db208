// rigger_cell_step [CELL_FILE [OUT_DIR]]: writes the simulated cell's load.step and target.step (and
// part.step, part_fixture.step when the cell has them).
// Defaults: deploy/cell/simulated_cell.json and deploy/cell/models of the source tree.

#include "cell_parts.hpp"

#include <iostream>

int main(int argc, char** argv) {
  const std::filesystem::path cell_path = argc > 1 ? argv[1] : RIGGER_SOURCE_DIR "/deploy/cell/simulated_cell.json";
  const std::filesystem::path out_dir = argc > 2 ? argv[2] : RIGGER_SOURCE_DIR "/deploy/cell/models";
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
