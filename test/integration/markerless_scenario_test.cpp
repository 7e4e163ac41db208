// The paper's scenario without markers, on every real process: the demo cell with no markers on the load and
// the target (deploy/cell/simulated_cell_markerless.json), rendered by cell_sim with MuJoCo and a
// structured-light sensor's depth noise. recipes/examples/crane_insert_markerless.json localizes both by their
// STEP models (Localize, method model) and InsertVisuallyGuided servoes on the vision tracker's model tracking
// (TRACK_CONTINUOUS of an object without markers). The task must SUCCEED with the load screwed on within 5 mm /
// 1 degree of its insertion pose in the physics. The servo's poses come at the rate the model tracking keeps
// (a few per second), so the admittance controller takes poses up to 0.5 s old (max_pose_age_s).
#include "scenario_support.hpp"

namespace rigger::testing::scenario {
namespace {

class MarkerlessScenarioTest : public MultiProcessTest {};

TEST_F(MarkerlessScenarioTest, CraneInsertByModelSucceedsWithinFiveMillimetresAndOneDegree) {
  ScenarioSetup setup;
  setup.cell_file = repo_file("deploy/cell/simulated_cell_markerless.json");
  setup.patches = {
      {"cell_sim",
       {{"camera",
         {{"renderer", "mujoco"},
          {"rate_hz", 5},
          {"depth_noise", {{"stddev_at_1m_m", 0.001}, {"grazing_deg", 80.0}, {"edge_gap_m", 0.01}}}}}}},
      {"admittance_control", {{"visual_servo", {{"max_pose_age_s", 0.5}}}}},
  };
  const auto scenario = ScenarioCell::on(cell_, setup);
  ScenarioCell& s = *scenario;
  ASSERT_TRUE(s.ready()) << "not every service came up";
  ASSERT_TRUE(s.submit("recipes/examples/crane_insert_markerless.json"));
  ASSERT_TRUE(s.wait_task_end(std::chrono::minutes(4))) << "the task did not end in time: " << s.task_summary();
  print_report(s, "crane insert without markers");
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();
  expect_screwed_on(s);
  EXPECT_FALSE(s.gripper_energized()) << "the robot should have let go at the end";
}

}  // namespace
}  // namespace rigger::testing::scenario
