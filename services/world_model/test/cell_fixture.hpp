#pragma once
// The cell files the world model tests read.

#include <string>

namespace rigger::world::testing {

// A frozen copy of the simulated cell: hand-computed expectations rely on its numbers.
inline std::string fixture_cell_path() {
  return std::string(RIGGER_SOURCE_DIR) + "/services/world_model/test/data/cell_fixture.json";
}

// The deployed cell configuration (the contract, which may change).
inline std::string shipped_cell_path() { return std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json"; }

}  // namespace rigger::world::testing
