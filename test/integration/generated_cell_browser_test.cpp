// The console on a cell the repository does not ship (rigger/sim/generated_cell.hpp: a table, a 25 kg
// L bracket, a flange with six holes and three loose parts, written with OpenCascade), in headless
// Debian chromium (planner/generated_cell.mjs): the real world model and CAD service on that cell's file
// and STEP models, scripted executors with the real skill library and the console, on a private DDS
// domain. The page draws the six objects from their STEP models, a click on a part fills a skill's
// object parameter, and the operator station highlights the flange's hole a prompt (written here over
// DDS) names. Then the programmer moves a loose part by a cell revision from the Tasks page (two steps),
// a viewer is refused it, and this test asks the world model over DDS where the part is now.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "planner_test_support.hpp"
#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "rigger/testing/require.hpp"
#include "world_query_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

// The loose part the revision moves, and by how much (world x, metres): along the table's far half.
constexpr const char* kMovedPart = "part_a";
constexpr double kMoveX = 0.05;

class GeneratedCellBrowserTest : public PlannerCellTest {
 protected:
  /// Starts the world model and the CAD service on `cell_file` (STEP models under `models`), the scripted
  /// executors and the console with a programmer, an operator and a viewer; waits until each is READY.
  ::testing::AssertionResult start(const std::string& cell_file, const std::string& models) {
    const std::string dir = cell_.log_dir();
    cell_.start("world_model", "world_model",
                {"--id", "world_model", "--config", write_config("world_model", {{"cell_config", cell_file}}), "--db",
                 dir + "/world_model.sqlite"});
    cell_.start(
        "cad", "cad",
        {"--id", "cad", "--config", write_config("cad", {{"cell_config", cell_file}, {"allowed_dirs", {models}}})});
    start_scripted_library_executors(cell_, {"Localize", "Screw"});
    const auto users = console::make_users(
        dir + "/console-users.json",
        {{"ada", console::Role::kProgrammer}, {"otto", console::Role::kOperator}, {"vera", console::Role::kViewer}});
    token_ = users[0].token;
    operator_token_ = users[1].token;
    viewer_token_ = users[2].token;
    port_ = free_tcp_port();
    cell_.start("console", "console",
                {"--id", "console", "--config",
                 write_config("console", {{"port", port_},
                                          {"users_file", dir + "/console-users.json"},
                                          {"audit_log", dir + "/console-audit.log"},
                                          {"runs_dir", dir + "/console-runs"},
                                          {"confirm_timeout_s", 30}})});
    if (!cell_.wait_ready({"world_model", "cad", "skills", "monitors", "console"}, 60s))
      return ::testing::AssertionFailure() << "the services did not all announce READY\n" << cell_.logs();
    return ::testing::AssertionSuccess();
  }

  /// A screw prompt for `hole` of the part `hole_ref` names (e.g. "h2", "flange/h2"), as the Screw skill
  /// writes it, once the console reads the topic.
  ::testing::AssertionResult write_screw_prompt(const std::string& id, const std::string& hole,
                                                const std::string& hole_ref) {
    prompts_ = std::make_unique<dds::Writer<rigger_operator_ui_OperatorPrompt>>(cell_.participant(),
                                                                                protocol::operator_ui::kPrompt);
    if (!prompts_->wait_for_readers(1, 20s)) return ::testing::AssertionFailure() << "the console never read prompts";
    operator_protocol::Prompt p;
    p.prompt_id = id;
    p.task_id = "generated-cell-screws";
    p.node_id = "root/1";
    p.kind = "screw";
    p.title = "Screw " + hole_ref;
    p.text = "Drive the screw into " + hole_ref;
    p.options = {"done", "failed", "abort"};
    p.details_json =
        json({{"hole", hole}, {"hole_ref", hole_ref}, {"screw_type", "M20x60"}, {"torque_nm", 120}}).dump();
    p.active = true;
    if (operator_protocol::write_prompt(*prompts_, p) != DDS_RETCODE_OK)
      return ::testing::AssertionFailure() << "the prompt was not written";
    return ::testing::AssertionSuccess();
  }

  std::string operator_token_, viewer_token_;
  std::unique_ptr<dds::Writer<rigger_operator_ui_OperatorPrompt>> prompts_;
};

TEST_F(GeneratedCellBrowserTest, PartsFromStepModelsPickedByClickFlangeHoleHighlightedAndRevisionApplied) {
  RIGGER_REQUIRE_OR_SKIP(
      browser_tools_present(),
      "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  const std::filesystem::path dir = cell_.log_dir() + "/generated";
  sim::GeneratedCell generated(dir, repo_file("deploy/cell/simulated_cell.json"));
  const std::string cell_file = generated.write().string();
  // The revision's file: the same cell with the loose part moved along x.
  json moved = generated.document();
  json& moved_pose = moved["entities"][generated.index_of(kMovedPart)]["pose"];
  const double x0 = moved_pose.at("position_m").at(0).get<double>();
  moved_pose["position_m"][0] = x0 + kMoveX;
  const std::string moved_file = (dir / "cell-moved.json").string();
  std::ofstream(moved_file) << moved.dump(2);

  // The flange's holes (flange frame, m) as the CAD rules derive them from its STEP model.
  json flange_holes = json::object();
  const cell::CellFile cad_cell = cell::load_cell_file_with_cad(cell_file);
  for (const auto& h : cad_cell.require("flange", "the test").features.screw_holes) {
    const Eigen::Vector3d p = h.pose_entity_hole.translation();
    flange_holes[h.id] = {p.x(), p.y(), p.z()};
  }
  ASSERT_EQ(flange_holes.size(), 6u) << flange_holes.dump();

  WorldQuery world(cell_);
  ASSERT_TRUE(start(cell_file, (dir / "models").string()));
  const auto before = world.pose(kMovedPart);
  ASSERT_TRUE(before.has_value()) << "the world model has no pose of " << kMovedPart << "\n" << cell_.logs();
  ASSERT_TRUE(write_screw_prompt("p-flange-h2", "h2", "flange/h2"));

  const std::string result_file = cell_.log_dir() + "/generated-cell-result.json";
  ASSERT_TRUE(run_browser_script("test/integration/planner/generated_cell.mjs", result_file, 3min,
                                 {{"TOKEN_OPERATOR", operator_token_},
                                  {"TOKEN_VIEWER", viewer_token_},
                                  {"FLANGE_HOLES", flange_holes.dump()},
                                  {"MOVED_CELL", moved_file},
                                  {"MOVED_PART", kMovedPart},
                                  {"MOVE_X_M", std::to_string(kMoveX)}}));
  std::ifstream in(result_file);
  const json result = json::parse(in);
  std::printf("result: %s\n", result.dump(2).c_str());

  // The world model, asked over DDS, has the part where the revision put it (the cell file's pose; the
  // world model has no physics moving it meanwhile).
  const auto after = world.pose(kMovedPart);
  ASSERT_TRUE(after.has_value()) << cell_.logs();
  const Eigen::Vector3d moved_by = after->translation() - before->translation();
  EXPECT_NEAR(moved_by.x(), kMoveX, 1e-3) << moved_by.transpose();
  EXPECT_NEAR(moved_by.y(), 0.0, 1e-3) << moved_by.transpose();
  EXPECT_NEAR(moved_by.z(), 0.0, 1e-3) << moved_by.transpose();
  std::printf("world model: %s moved by %.4f mm along x (%.4f, %.4f mm along y, z)\n", kMovedPart, 1000 * moved_by.x(),
              1000 * moved_by.y(), 1000 * moved_by.z());
  // The revision is journaled with who, in the console's audit log too.
  std::ifstream audit(cell_.log_dir() + "/console-audit.log");
  const std::string audit_text{std::istreambuf_iterator<char>(audit), std::istreambuf_iterator<char>()};
  EXPECT_NE(audit_text.find("cell apply"), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", cell_.log_dir().c_str());
}

}  // namespace
}  // namespace rigger::testing
