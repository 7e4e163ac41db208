// The scenario on a cell the repository does not ship: the generated cell (rigger_generated_cell: a fixture
// table, a 25 kg L bracket on the crane's rope, a flange plate with six holes, three loose parts; STEP models
// written with OpenCascade in the test) under every real process of the scenario, each given its path. The
// scenario's recipe with the cell's feature names (GeneratedCell::recipe) must run to SUCCEEDED in physics,
// the bracket screwed on within 5 mm / 1 degree of its CAD insertion pose on the flange.
#include <fstream>

#include "rigger/sim/generated_cell.hpp"
#include "scenario_support.hpp"

namespace rigger::testing::scenario {
namespace {

class GeneratedCellScenarioTest : public MultiProcessTest {
 protected:
  GeneratedCellScenarioTest()
      : files_(cell_.log_dir() + "/generated", repo_file("deploy/cell/simulated_cell.json")),
        cell_path_(files_.write()) {}

  sim::GeneratedCell files_;
  std::filesystem::path cell_path_;
};

TEST_F(GeneratedCellScenarioTest, CraneInsertSucceedsOnTheBracketAndFlange) {
  const auto cell = ScenarioCell::on(cell_, ScenarioSetup{cell_path_.string(), "bracket", "flange"});
  ScenarioCell& s = *cell;
  ASSERT_TRUE(s.ready()) << "not every service came up";
  std::ifstream in(repo_file("recipes/crane_insert.json"));
  ASSERT_TRUE(s.submit_json(files_.recipe(nlohmann::json::parse(in), "crane-insert-bracket")));
  ASSERT_TRUE(s.wait_task_end(std::chrono::minutes(4))) << "the task did not end in time: " << s.task_summary();
  print_report(s, "crane insert on the generated cell");
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();
  // Measured as the scenario measures the shipped cell: the truth when the release started.
  expect_screwed_on(s);
  EXPECT_TRUE(s.ever_held());
  EXPECT_FALSE(s.gripper_energized()) << "the robot should have let go at the end";
}

}  // namespace
}  // namespace rigger::testing::scenario
