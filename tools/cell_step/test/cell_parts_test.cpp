// The committed STEP files of the cell's parts (deploy/cell/models) are current: regenerated from the
// cell file they have the same geometry (STEP bytes carry a timestamp, so geometry is compared), and
// the cell file's screw holes h1..h4, derived from them, are their holes.

#include "cell_parts.hpp"

#include "rigger/cad/features.hpp"
#include "rigger/cell_config/cell_cad.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

namespace rigger::cad {
namespace {

namespace fs = std::filesystem;
const fs::path kSource = RIGGER_SOURCE_DIR;

TEST(CellParts, CommittedStepFilesAreCurrent) {
  const auto cell = cell::load_cell_file(kSource / "deploy/cell/simulated_cell.json");
  const auto parts = cell_parts(cell);
  const fs::path dir = fs::temp_directory_path() / ("rigger_cell_parts_" + std::to_string(::getpid()));
  write_cell_parts(parts, dir);
  for (const auto& part : parts) {
    SCOPED_TRACE(part.file_name);
    const Features committed = classify(read_step_file(kSource / "deploy/cell/models" / part.file_name));
    const Features fresh = classify(read_step_file(dir / part.file_name));
    ASSERT_EQ(committed.faces.size(), fresh.faces.size()) << "run rigger_cell_step to regenerate";
    ASSERT_EQ(committed.edges.size(), fresh.edges.size());
    for (std::size_t i = 0; i < fresh.faces.size(); ++i) {
      EXPECT_TRUE(same_signature(committed.faces[i].signature, fresh.faces[i].signature, 1e-9, 1e-9))
          << "face " << i << " differs: run rigger_cell_step to regenerate";
    }
    ASSERT_EQ(committed.holes.size(), part.holes.size());
  }
  fs::remove_all(dir);
}

TEST(CellParts, ScrewHolesOfTheTargetAreHolesOfItsModel) {
  // The cell file names the holes by reference (rigger_cell_cad derives their frames); each derived
  // frame is the entry and axis of exactly one hole of the committed model.
  const auto cell = cell::load_cell_file_with_cad(kSource / "deploy/cell/simulated_cell.json");
  const Features target = classify(read_step_file(kSource / "deploy/cell/models/target.step"));
  const auto& holes = cell.find("target")->features.screw_holes;
  ASSERT_EQ(holes.size(), 4u);
  for (const auto& screw : holes) {
    SCOPED_TRACE(screw.id);
    int matches = 0;
    for (const auto& hole : target.holes) {
      if ((hole.entry_m - screw.pose_entity_hole.translation()).norm() < 1e-6 &&
          (hole.axis - screw.pose_entity_hole.linear().col(2)).norm() < 1e-6) {
        ++matches;
      }
    }
    EXPECT_EQ(matches, 1);
  }
}

}  // namespace
}  // namespace rigger::cad
