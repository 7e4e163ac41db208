// An object whose geometry is its STEP model alone gets the shape kind "step" and its model's bounding
// box in the world model's JSON; a model that cannot be read is refused with the file and pointer.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "rigger/cell_config/cell_cad.hpp"
#include "step_model_bounds.hpp"
#include "world_json.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

const std::filesystem::path kCellDir = std::filesystem::path(RIGGER_SOURCE_DIR) / "deploy/cell";

cell::ObjectModel& model_of(CellConfig& cell, const std::string& id) {
  for (cell::CellEntity& entity : cell.entities) {
    if (entity.id == id) return *entity.model;
  }
  throw std::out_of_range(id);
}

// The demo cell (its CAD features derived) with the load's box shorthand removed: its geometry is
// models/load.step alone (a 0.40 x 0.30 x 0.20 m box about its frame).
CellConfig step_only_load() {
  CellConfig cell = cell::load_cell_file_with_cad(kCellDir / "simulated_cell.json");
  cell::ObjectModel& load = model_of(cell, "load");
  load.shape.clear();
  load.size_m.setZero();
  return cell;
}

TEST(StepModelBounds, AStepOnlyObjectGetsItsKindAndBoundingBox) {
  CellConfig cell = step_only_load();
  describe_step_models(cell, {}, kCellDir);
  const cell::ObjectModel& load = model_of(cell, "load");
  EXPECT_EQ(load.shape, "step");
  EXPECT_NEAR(load.size_m.x(), 0.40, 1e-6);
  EXPECT_NEAR(load.size_m.y(), 0.30, 1e-6);
  EXPECT_NEAR(load.size_m.z(), 0.20, 1e-6);
  EXPECT_EQ(model_of(cell, "target").shape, "box");  // a box stays a box

  const WorldStore store = WorldStore::from_config(cell, std::chrono::system_clock::now());
  const nlohmann::json json = entity_to_json(*store.find("load"));
  EXPECT_EQ(json["model"]["shape"], "step");
  EXPECT_NEAR(json["model"]["size_m"][0].get<double>(), 0.40, 1e-6);
}

TEST(StepModelBounds, AnUnreadableModelIsRefusedWithItsPointer) {
  CellConfig cell = step_only_load();
  model_of(cell, "load").step = "models/no_such.step";
  try {
    describe_step_models(cell, {}, kCellDir);
    FAIL() << "a missing STEP model was accepted";
  } catch (const CellConfigError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/entities/"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/model/step"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("models/no_such.step"));
  }
}

}  // namespace
}  // namespace rigger::world
