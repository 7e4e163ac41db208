#include "rigger/sim/cell_geometry.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace rigger::sim {
namespace {

using ::testing::HasSubstr;

std::string read_file(const std::string& path) {
  std::ifstream stream(path);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

std::string shared_cell_text() { return read_file(RIGGER_CELL_JSON); }

// Replaces the first occurrence of `from` (which must exist) in the shared cell JSON.
std::string shared_cell_with(const std::string& from, const std::string& to) {
  std::string text = shared_cell_text();
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not in the cell JSON";
  if (at != std::string::npos) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string parse_error(const std::string& text) {
  try {
    // The cell's STEP models (for its CAD rules) are those next to the shared cell file.
    parse_cell_geometry(text, "cell.json", std::filesystem::path(RIGGER_CELL_JSON).parent_path());
  } catch (const CellGeometryError& error) {
    return error.what();
  }
  return "";
}

TEST(CellGeometry, ReadsTheSharedCellFile) {
  const CellGeometry cell = load_cell_geometry(RIGGER_CELL_JSON);
  EXPECT_DOUBLE_EQ(cell.crane.rail_height_m, 4.5);
  EXPECT_DOUBLE_EQ(cell.crane.bridge_range_m[1], 8.0);
  EXPECT_DOUBLE_EQ(cell.crane.rope_length_range_m[0], 0.5);
  EXPECT_DOUBLE_EQ(cell.crane.max_speed_mps[2], 0.2);
  EXPECT_DOUBLE_EQ(cell.gripper.holding_force_n, 1200.0);
  EXPECT_DOUBLE_EQ(cell.gripper.flange_to_face_m, 0.12);
  EXPECT_EQ(cell.robot.model, "kuka_lbr_iiwa_14_r820");
  EXPECT_TRUE(cell.load.size_m.isApprox(Eigen::Vector3d(0.40, 0.30, 0.20)));
  EXPECT_DOUBLE_EQ(cell.load.mass_kg, 40.0);
  EXPECT_TRUE(cell.load.pose_world_load.translation().isApprox(Eigen::Vector3d(3.55, 1.75, 1.20)));
  EXPECT_TRUE(
      cell.load.pose_load_rope_attachment.translation().isApprox(Eigen::Vector3d(0, 0, 0.10)));
  ASSERT_TRUE(cell.grasp_frame("grasp_side").has_value());
  EXPECT_FALSE(cell.grasp_frame("grasp_top").has_value());
  ASSERT_TRUE(cell.load.pose_target_load_inserted.has_value());
  EXPECT_TRUE(
      cell.load.pose_target_load_inserted->translation().isApprox(Eigen::Vector3d(0, 0, 0.10)));
  EXPECT_TRUE(cell.target.size_m.isApprox(Eigen::Vector3d(0.50, 0.40, 0.95)));
}

TEST(CellGeometry, GraspSideFrameHasToolZIntoTheMinusXFaceAndToolXDown) {
  const CellGeometry cell = load_cell_geometry(RIGGER_CELL_JSON);
  const Eigen::Isometry3d grasp = *cell.grasp_frame("grasp_side");
  EXPECT_TRUE(grasp.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-9));
  EXPECT_TRUE(grasp.linear().col(0).isApprox(-Eigen::Vector3d::UnitZ(), 1e-9));
  EXPECT_NEAR(grasp.translation().x(), -0.20, 1e-12);  // on the -x face
}

TEST(CellGeometry, ErrorsNameFileAndJsonPointer) {
  EXPECT_THAT(parse_error(shared_cell_with(R"("mass_kg": 40.0)", R"("mass_kg": -40.0)")),
              AllOf(HasSubstr("cell.json: /entities/5/model/mass_kg: expected a number > 0")));
  EXPECT_THAT(parse_error(shared_cell_with(R"("mass_kg": 40.0, )", "")),
              HasSubstr("/entities/5/model/mass_kg: expected the mass of a free object: mass_kg > 0, or density_kg_m3 > 0 "
                        "with a STEP model"));
  // An object needs a geometry: the box shorthand or a STEP model.
  EXPECT_THAT(parse_error(shared_cell_with(R"("shape": "box", "size_m": [0.14, 0.24, 0.12], "mass_kg": 3.0, "frame": "box centre", "step": "models/part.step")",
                                           R"("mass_kg": 3.0)")),
              HasSubstr("cell.json: /entities/8/model: expected a geometry: \"shape\": \"box\" with \"size_m\", or a "
                        "STEP model (\"step\"), got neither"));
  EXPECT_THAT(parse_error(shared_cell_with(R"("mass_kg": 3.0, "frame": "box centre")", R"("density_kg_m3": 0, "frame": "box centre")")),
              HasSubstr("cell.json: /entities/8/model/density_kg_m3: expected a number > 0"));
  // The crane carries one load.
  EXPECT_THAT(parse_error(shared_cell_with(R"("rope_attachment": { "position_m": [0, 0, 0.10], "rpy_deg": [0, 0, 0] },)", "")),
              HasSubstr("cell.json: /entities: expected an object with features.rope_attachment (the crane's load)"));
  EXPECT_THAT(parse_error(shared_cell_with(R"("rail_height_m": 4.5,)", "")),
              HasSubstr("/entities/1/attributes/rail_height_m: expected a number > 0, got nothing (missing key)"));
  EXPECT_THAT(parse_error(shared_cell_with(R"("bridge_range_m": [0.0, 8.0])", R"("bridge_range_m": [8.0, 0.0])")),
              AllOf(HasSubstr("/entities/1/attributes/bridge_range_m"), HasSubstr("min < max")));
  EXPECT_THAT(parse_error(shared_cell_with(R"("holding_force_n": 1200)", R"("holding_force_n": "strong")")),
              HasSubstr("/entities/3/attributes/holding_force_n: expected a number, got string \"strong\""));
  EXPECT_THAT(parse_error(shared_cell_with(R"("model": "kuka_lbr_iiwa_14_r820")", R"("model": "ur10")")),
              HasSubstr("/entities/2/attributes/model: expected \"kuka_lbr_iiwa_14_r820\""));
  EXPECT_THAT(parse_error(shared_cell_with(R"("rope_length_range_m": [0.5, 3.8])", R"("rope_length_range_m": [0.5, 4.8])")),
              HasSubstr("rail_height_m"));
  EXPECT_THAT(parse_error(shared_cell_with(R"("max_accel_mps2": [0.5, 0.5, 0.3])", R"("max_accel_mps2": [0.5, 0.5])")),
              HasSubstr("/entities/1/attributes/max_accel_mps2: expected an array of 3 numbers > 0"));
  // The insertion is derived from the target's STEP model: another target must have one.
  EXPECT_THAT(parse_error(shared_cell_with(R"("insertion": { "target": "target")", R"("insertion": { "target": "robot")")),
              HasSubstr("/entities/5/features/insertion/cad/target_face: expected an insertion target whose model "
                        "names a STEP file"));
}

TEST(CellGeometry, NeedsTheModelledEntities) {
  EXPECT_THAT(parse_error(shared_cell_with(R"("id": "gripper")", R"("id": "magnet")")),
              HasSubstr("cell.json: /entities: expected an entity with id \"gripper\""));
  // The cell file's own rules are the shared reader's (common/cell_config/test); its errors come through.
  EXPECT_THAT(parse_error("{ \"entities\": [ "), HasSubstr("cell.json: (document): expected valid JSON"));
  try {
    load_cell_geometry("/nonexistent/cell.json");
    FAIL() << "expected CellGeometryError";
  } catch (const CellGeometryError& error) {
    EXPECT_THAT(error.what(), HasSubstr("/nonexistent/cell.json"));
  }
}

}  // namespace
}  // namespace rigger::sim
