// Pick and Place in physics: recipes/examples/pick_and_place.json on every real process of the
// cell (cell_sim with MuJoCo and its camera, world_model, vision_tracker, the skill executors, monitor_host,
// task_controller; the crane's processes run too, untouched). The tracker localizes the small part by its
// marker, Pick grasps it off its table with the magnet, Place sets it down at the recipe's pose on the same
// table; the test asserts the part's true pose (rigger/sim/ground_truth) at the end against that pose.
#include <cmath>
#include <fstream>

#include "scenario_support.hpp"
#include "world_query_support.hpp"

namespace rigger::testing::scenario {
namespace {

constexpr auto kTaskTimeout = std::chrono::minutes(4);
constexpr const char* kRecipe = "recipes/examples/pick_and_place.json";

Eigen::Isometry3d pose_from_json(const nlohmann::json& pose) {
  const auto p = pose.at("position_m").get<std::vector<double>>();
  const auto rpy = pose.at("rpy_deg").get<std::vector<double>>();
  const double deg = M_PI / 180.0;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = (Eigen::AngleAxisd(rpy[2] * deg, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(rpy[1] * deg, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(rpy[0] * deg, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  out.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return out;
}

/// Where the recipe puts the part: the Place pose is the tool (magnet face centre, z into the part) at the
/// release, in the frame of the feature it names; the part hangs below the tool as Pick grasped it (the
/// cell file's grasp_top: the tool at the top-face centre, z down), and once let go it rests on the table,
/// i.e. the release height above the part's top face lower.
Eigen::Isometry3d place_goal_world_part() {
  const cell::CellFile cell = cell::load_cell_file_with_cad(repo_file("deploy/cell/simulated_cell.json"));
  std::ifstream in(repo_file(kRecipe));
  const nlohmann::json recipe = nlohmann::json::parse(in);
  const nlohmann::json& place = recipe.at("root").at("children").at(2).at("child").at("children").at(0);
  if (place.at("skill") != "Place") throw std::runtime_error("the recipe's third step is not the Place");
  const nlohmann::json& pose = place.at("params").at("pose");
  const std::string frame = pose.at("frame").get<std::string>();
  const std::string entity = frame.substr(0, frame.find('/'));
  const std::string feature = frame.substr(frame.find('/') + 1);
  const cell::CellEntity& table = cell.require(entity, "the place frame's entity");
  const cell::NamedPose* place_frame = nullptr;
  for (const auto& w : table.features.approach_waypoints)
    if (w.id == feature) place_frame = &w;
  if (place_frame == nullptr) throw std::runtime_error("no approach waypoint " + frame + " in the cell file");
  const cell::CellEntity& part = cell.require("part", "the part the recipe moves");
  const cell::NamedPose* grasp = nullptr;
  for (const auto& g : part.features.grasp_frames)
    if (g.id == "grasp_top") grasp = &g;
  if (grasp == nullptr) throw std::runtime_error("no grasp frame part/grasp_top in the cell file");

  const Eigen::Isometry3d world_tool =
      cell.pose_root_entity(entity) * place_frame->pose_entity_feature * pose_from_json(pose);
  // The part in the tool frame as grasped, then lowered onto the table by the release gap: the tool's z
  // above the top face at the release is -(place z) - the part's height, in the place frame (z down).
  const double gap_m = -pose.at("position_m").at(2).get<double>() - part.model->size_m.z();
  Eigen::Isometry3d world_part = world_tool * grasp->pose_entity_feature.inverse();
  world_part.translation() += world_tool.linear().col(2) * gap_m;
  return world_part;
}

class PickPlaceCellTest : public MultiProcessTest {};

// The part is localized by its marker, picked off its table, placed at the recipe's pose: the task SUCCEEDS
// and the part's true pose ends within 5 mm and 2 degrees of where the recipe puts it; the magnet is off.
TEST_F(PickPlaceCellTest, PickAndPlaceRecipeMovesThePartInPhysics) {
  const Eigen::Isometry3d goal = place_goal_world_part();
  ScenarioCell s(cell_);
  WorldQuery world(cell_);
  ASSERT_TRUE(s.ready()) << "not every service came up";
  ASSERT_TRUE(cell_.wait_until([&] { return s.truth("part").has_value(); }, 10s)) << "no ground truth of the part";
  const Eigen::Isometry3d start = *s.truth("part");
  ASSERT_GT((goal.translation() - start.translation()).norm(), 0.1) << "the place pose is where the part already is";

  ASSERT_TRUE(s.submit(kRecipe));
  ASSERT_TRUE(s.wait_task_end(kTaskTimeout)) << "the task did not end in time: " << s.task_summary();
  std::printf("--- pick and place: task %s after %.1f s\n%s", s.task_code().c_str(), s.task_seconds(),
              s.durations().c_str());
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();
  EXPECT_TRUE(s.ever_held()) << "the magnet never held the part";
  EXPECT_FALSE(s.gripper_energized()) << "the robot should have let go";

  // The part has come to rest on the table: its true pose stops changing.
  Eigen::Isometry3d last = *s.truth("part");
  int still = 0;
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        const Eigen::Isometry3d now = *s.truth("part");
        still = (now.translation() - last.translation()).norm() < 1e-5 ? still + 1 : 0;
        last = now;
        return still >= 50;
      },
      10s))
      << "the part does not come to rest";
  const Eigen::Isometry3d end = *s.truth("part");
  const double error_m = (end.translation() - goal.translation()).norm();
  const double error_rad = Eigen::AngleAxisd(goal.linear() * end.linear().transpose()).angle();
  const Eigen::Vector3d d = end.translation() - goal.translation();
  std::printf(
      "  part moved %.1f mm; final pose vs the place goal (ground truth): %.2f mm (x %.2f, y %.2f, z %.2f), "
      "%.2f deg\n",
      (end.translation() - start.translation()).norm() * 1000.0, error_m * 1000.0, d.x() * 1000.0, d.y() * 1000.0,
      d.z() * 1000.0, error_rad * 180.0 / M_PI);
  EXPECT_LT(error_m, 0.005) << "the part is not where the recipe places it";
  EXPECT_LT(error_rad, 2.0 * M_PI / 180.0);
  for (const char* name : {"localize part", "pick part", "place part"}) {
    const NodeView* n = s.node(name);
    ASSERT_NE(n, nullptr) << name;
    EXPECT_EQ(n->state, rigger_task_NODE_SUCCESS) << name;
  }
  // The world model no longer claims the pose the part was picked at: Place told it the part moved.
  const auto localized = world.localized("part");
  ASSERT_TRUE(localized.has_value()) << "the world model did not answer";
  EXPECT_FALSE(*localized) << "the world model still says the part is localized where it was picked";
}

}  // namespace
}  // namespace rigger::testing::scenario
