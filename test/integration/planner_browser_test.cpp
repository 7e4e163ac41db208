// The console's planner in a real browser: the real CAD service (the cell's STEP
// models), the real world model, the task controller, scripted executors announcing the real skill
// library (recipes/examples/skill_library.json), and the console, all on a private DDS domain; headless
// Debian chromium driven by playwright-core (planner/e2e.mjs) builds a tree by clicks, picks the
// target's holes in the 3D view, binds the Screw skill's holes, sees a bad Parallel threshold flagged on
// its node and field, fixes it, exports and publishes. This test checks what the system did: the
// exported recipe validates and carries the CAD-derived screw positions, and the published task ran.
// The second test (planner/errors.mjs) checks the editing errors on their nodes and fields and that
// Publish is refused while the tree has them.
#include <algorithm>
#include <array>
#include <fstream>
#include <map>
#include <memory>
#include <set>

#include <nlohmann/json.hpp>

#include "planner_test_support.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/cad/assembly.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "world_query_support.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

/// The planner's services, the controller's task states followed (task id → last state) from before they
/// start, and a browser script run against them.
class PlannerBrowserTest : public PlannerCellTest {
 protected:
  /// Starts the services, runs `script` and reads its result (RESULT, `result_name` in the log folder).
  ::testing::AssertionResult run_script(const std::string& script, const std::string& result_name,
                                        std::chrono::milliseconds timeout, json& result,
                                        std::map<std::string, std::string> env = {}) {
    status_ = std::make_unique<dds::Reader<rigger_task_TaskStatus>>(cell_.participant(), protocol::task::kStatus);
    cell_.loop().on_data(*status_, [this] {
      status_->take([this](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
        task_states_[dds::to_string(s.task_id)] = s.state;
      });
    });
    if (auto started = start_planner_services(); !started) return started;
    const std::string result_file = cell_.log_dir() + "/" + result_name;
    if (auto ran = run_browser_script(script, result_file, timeout, std::move(env)); !ran) return ran;
    std::ifstream in(result_file);
    result = json::parse(in);
    return ::testing::AssertionSuccess();
  }
  /// The console's audit log so far (empty when nothing was audited).
  std::string audit_log() {
    std::ifstream audit(cell_.log_dir() + "/console-audit.log");
    return {std::istreambuf_iterator<char>(audit), std::istreambuf_iterator<char>()};
  }

  std::map<std::string, int> task_states_;
  std::unique_ptr<dds::Reader<rigger_task_TaskStatus>> status_;
};

TEST_F(PlannerBrowserTest, TreeBuiltByClicksScrewsFromPickedHolesValidatedExportedAndPublished) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  json result;
  ASSERT_TRUE(run_script("test/integration/planner/e2e.mjs", "planner-result.json", std::chrono::minutes(6), result));
  // The exported recipe is canonical JSON and its Screw node's holes are the world model's features,
  // with the binding (model sha256, references with signatures, CAD-derived poses) kept.
  const std::string exported = result.at("exported");
  const json recipe = json::parse(exported);
  EXPECT_EQ(exported, recipe.dump(2) + "\n") << "the export is not in canonical form";
  const json& screw = recipe.at("root").at("children").at(1);
  ASSERT_EQ(screw.at("skill"), "Screw") << recipe.dump(2);
  const json& binding = screw.at("bindings").at("holes");
  const json& cad_holes = result.at("cad_holes");
  ASSERT_EQ(binding.at("screws").size(), 4u);
  ASSERT_EQ(screw.at("params").at("holes").size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const json& s = binding.at("screws").at(i);
    EXPECT_EQ(s.at("ref").at("model_sha256"), binding.at("model_sha256"));
    EXPECT_TRUE(s.at("ref").at("signature").contains("radius_m"));
    EXPECT_EQ(screw.at("params").at("holes").at(i), s.at("feature"));
    // The picks were in the order h0, h1, h2, h3 of the CAD model: the positions are the CAD service's.
    EXPECT_EQ(s.at("hole"), cad_holes.at(i).at("index"));
    EXPECT_EQ(s.at("pose").at("position_m"), cad_holes.at(i).at("entry_m"));
  }
  // The page showed the Parallel's threshold error on that node and field, from the controller's validator.
  EXPECT_EQ(result.at("threshold_error").at("node"), "/root/children/0");
  EXPECT_NE(result.at("threshold_error").at("field").get<std::string>().find("success_threshold"), std::string::npos);

  // Published with the two-step confirmation: the controller ran the planned task to the end.
  const std::string task_id = recipe.at("task_id");
  ASSERT_TRUE(cell_.wait_until([&] {
    auto it = task_states_.find(task_id);
    return it != task_states_.end() && (it->second == rigger_task_TASK_SUCCEEDED || it->second == rigger_task_TASK_FAILED ||
                                       it->second == rigger_task_TASK_REJECTED);
  }, 60s)) << "the published task did not end\n" << cell_.logs();
  EXPECT_EQ(task_states_[task_id], rigger_task_TASK_SUCCEEDED) << protocol::task::task_state_name(task_states_[task_id]);
  const std::string audit_text = audit_log();
  EXPECT_NE(audit_text.find("\"action\":\"publish\""), std::string::npos) << audit_text;
  std::printf("browser artifacts in %s\n", cell_.log_dir().c_str());
}

// The planner's rule "editing errors are shown on the right node and field, and publishing is refused"
// (planner/errors.mjs): one tree built by clicks with an impossible Parallel threshold, two branches
// claiming the robot and an insertion whose preconditions nothing provides; the page shows each on its
// node and field (or the condition or resource it names), and refuses Publish. Nothing reaches the
// controller: the console never had a publish selected and no task status names the task.
TEST_F(PlannerBrowserTest, EditingErrorsShownOnTheirNodesAndFieldsAndPublishRefused) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  json result;
  ASSERT_TRUE(run_script("test/integration/planner/errors.mjs", "planner-errors-result.json", std::chrono::minutes(4), result));
  // Each error where it belongs, as the page showed it (the script checked the page; this is the record).
  EXPECT_EQ(result.at("threshold").at("node"), "/root/children/1");
  EXPECT_EQ(result.at("threshold").at("field"), "success_threshold");
  EXPECT_EQ(result.at("conflict").at("node"), "/root/children/1/children/1");
  EXPECT_EQ(result.at("conflict").at("claims").size(), 2u) << result.dump(2);
  EXPECT_EQ(result.at("preconditions").at("node"), "/root/children/0");
  EXPECT_EQ(result.at("preconditions").at("unmet"),
            json({"attached(robot,load)", "localized(load)", "localized(target)"}));
  EXPECT_EQ(result.at("publish_notice").get<std::string>().rfind("Not published", 0), 0u) << result.dump(2);

  // Publish was refused in the page: the console never selected a publish (the audit log records every
  // POST /api/recipes), so nothing was sent, and no task status names the task.
  const std::string task_id = result.at("task_id");
  const std::string audit_text = audit_log();
  EXPECT_EQ(audit_text.find("publish"), std::string::npos) << audit_text;
  EXPECT_EQ(task_states_.count(task_id), 0u) << protocol::task::task_state_name(task_states_[task_id]);
  std::printf("browser artifacts in %s\n", cell_.log_dir().c_str());
}

// A part placed by picks (planner/place.mjs): the load's bottom face, clicked from below, laid on the
// target's top face at a point off its centre, turned a quarter, confirmed. The world model's new poses
// put the two picked points together with the faces' normals opposite and the load turned a quarter;
// the console audited the selection and the revision.
TEST_F(PlannerBrowserTest, APartPlacedByPicksBecomesACellRevisionWithItsFaceOnTheOther) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  WorldQuery world(cell_);
  json result;
  ASSERT_TRUE(run_script("test/integration/planner/place.mjs", "planner-place-result.json", std::chrono::minutes(3), result));
  const auto vector = [](const json& v) { return Eigen::Vector3d(v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>()); };
  const auto load = world.pose("load");
  const auto target = world.pose("target");
  ASSERT_TRUE(load && target);
  const Eigen::Vector3d own = *load * vector(result.at("own").at("point_m"));
  const Eigen::Vector3d onto = *target * vector(result.at("onto").at("point_m"));
  EXPECT_LT((own - onto).norm(), 1e-6) << own.transpose() << " vs " << onto.transpose();
  EXPECT_NEAR((load->linear() * vector(result.at("own").at("normal")))
                  .dot(target->linear() * vector(result.at("onto").at("normal"))),
              -1.0, 1e-9);
  EXPECT_EQ(world.localized("load"), std::optional<bool>(true)) << "placed as known, no Localize needed";
  // A quarter turn about the target's top face: the load's x lies along the target's y.
  EXPECT_NEAR((load->linear() * Eigen::Vector3d::UnitX()).dot(target->linear() * Eigen::Vector3d::UnitY()), 1.0, 1e-9);
  const std::string audit_text = audit_log();
  EXPECT_NE(audit_text.find(R"("action":"select cell place load")"), std::string::npos) << audit_text;
  EXPECT_NE(audit_text.find(R"("action":"cell place load")"), std::string::npos) << audit_text;
  std::printf("%s; browser artifacts in %s\n", result.value("notice", "").c_str(), cell_.log_dir().c_str());
}

// A STEP file the repository does not ship imported in the planner (planner/import.mjs): the generated
// cell's flange plate, written with OpenCascade here. The page showed what it holds and drew it, a click
// picked its face; a file that is not STEP was refused on the page; the file became a cell object (its
// bytes sent with the revision) and was placed by picks. The console audited the reads and revisions.
// Then an assembly written here: its sheet (a node without a solid) was refused on the page when chosen,
// and its sub-assembly "frame" chosen in the product tree became an object alone, its model the node's
// own STEP file (the same bytes as extracted here) with exactly its holes.
TEST_F(PlannerBrowserTest, AStepFileImportedInThePlannerIsShownDrawnAndPickable) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  const sim::GeneratedCell generated(cell_.log_dir() + "/generated", repo_file("deploy/cell/simulated_cell.json"));
  const std::string not_step = cell_.log_dir() + "/notes.step";
  std::ofstream(not_step) << "these are notes, not a STEP file\n";
  const std::filesystem::path assembly = cell_.log_dir() + "/cell_assembly.step";
  cad::write_step_assembly(cad::parts::test_assembly_with_a_sheet(), assembly);
  json result;
  ASSERT_TRUE(run_script("test/integration/planner/import.mjs", "planner-import-result.json", std::chrono::minutes(4),
                         result, {{"FLANGE", (generated.dir() / "models/flange.step").string()}, {"NOT_STEP", not_step},
                                  {"ASSEMBLY", assembly.string()}}));
  EXPECT_EQ(result.at("model").get<std::string>().rfind("sha256:", 0), 0u) << result.dump(2);
  EXPECT_EQ(result.at("pick").at("sha256").get<std::string>(), result.at("model").get<std::string>().substr(7));
  const std::string audit_text = audit_log();
  EXPECT_NE(audit_text.find(R"("action":"import STEP","result":"read as sha256:)"), std::string::npos) << audit_text;
  EXPECT_NE(audit_text.find(R"("action":"import STEP","result":"refused: CAD_)"), std::string::npos) << audit_text;
  // Made a cell object, placed, its insertion, a marker and its rope attachment declared: five confirmed
  // revisions, the taken name and the marker too large for its face refused before they reached any.
  EXPECT_EQ(result.at("revision_after"), result.at("revision_before").get<std::uint64_t>() + 5) << result.dump(2);
  // The rope hooks at the picked hole's entry.
  const json& rope = result.at("rope_attachment");
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(rope.at("position_m").at(i).get<double>(), result.at("hole_entry").at(i).get<double>(), 1e-6) << rope.dump();
  // The insertion the world model derived: the flange's bottom face (at z = b in its own frame) on the
  // target's top face (the target's frame), so the flange's frame sits -b above the target's.
  const json& insertion = result.at("insertion");
  EXPECT_NEAR(insertion.at("pose_in_target").at("position_m").at(2).get<double>(),
              -result.at("bottom_z").get<double>(), 1e-6)
      << insertion.dump(2);
  EXPECT_NE(audit_text.find("cell add flange_imported"), std::string::npos) << audit_text;
  EXPECT_EQ(audit_text.find("cell add part\""), std::string::npos) << "the taken name reached the world model";
  // The node added: the bytes this test extracts from the same file, the world model's box of the frame
  // in its own frame, and the CAD service's holes of the object: the plate's three and the bracket's two
  // where the frame places them, nothing else.
  const json& node = result.at("assembly");
  EXPECT_EQ(node.at("node_sha256"), sha256_hex(cad::extract_step_node(assembly, {0}).step)) << node.dump(2);
  const std::array<double, 3> frame_size{0.3, 0.2, 0.06};
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(node.at("size_m").at(i).get<double>(), frame_size[i], 1e-6) << node.dump(2);
  std::vector<std::pair<Eigen::Vector3d, double>> expected;
  for (const auto& [instance, holes] : {std::pair{"plate_1", cad::parts::plate_holes()}, std::pair{"bracket_1", cad::parts::bracket_holes()}})
    for (const auto& hole : holes) expected.emplace_back(cad::parts::test_assembly_pose(instance) * hole.entry_m, hole.diameter_m);
  ASSERT_EQ(node.at("holes").size(), expected.size()) << node.dump(2);
  for (const auto& [entry, diameter] : expected) {
    const auto found = std::count_if(node.at("holes").begin(), node.at("holes").end(), [&](const json& h) {
      const Eigen::Vector3d at(h.at("entry_m").at(0).get<double>(), h.at("entry_m").at(1).get<double>(), h.at("entry_m").at(2).get<double>());
      return (at - entry).norm() < 1e-6 && std::abs(h.at("diameter_m").get<double>() - diameter) < 1e-6;
    });
    EXPECT_EQ(found, 1) << "a hole of " << diameter << " m at " << entry.transpose() << ": " << node.dump(2);
  }
  std::printf("%s; browser artifacts in %s\n", result.value("summary", "").c_str(), cell_.log_dir().c_str());
}

// Features declared by picks (planner/declare.mjs): screw holes "all like" a picked hole and a grasp
// frame from the top face and an edge of it, each a confirmed cell revision; a taken name refused first.
// This test checks what the world model serves afterwards: the rules it derived from the committed document.
// Then a new version of the target's STEP model, its first hole drilled 2 mm further out (written here with
// OpenCascade), replaces the target's model: the rules into the hole that moved are named and dropped.
TEST_F(PlannerBrowserTest, FeaturesDeclaredByPicksAreServedByTheWorldModel) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  const std::string moved = cell_.log_dir() + "/target_moved.step";
  auto drilled = cad::parts::cell_target_holes();
  drilled.at(0).entry_m.x() -= 0.002;
  const Eigen::Vector3d half(0.25, 0.20, 0.0);  // deploy/cell/simulated_cell.json: the target is 0.50 x 0.40 x 0.95 m
  cad::write_step(cad::parts::drilled_box(-half - Eigen::Vector3d(0, 0, 0.95), half, drilled), "target", moved);
  json result;
  ASSERT_TRUE(run_script("test/integration/planner/declare.mjs", "planner-declare-result.json", std::chrono::minutes(4),
                         result, {{"TARGET_MOVED", moved}}));
  EXPECT_EQ(result.at("revision_after"), result.at("revision_before").get<std::uint64_t>() + 2) << result.dump(2);
  const json& features = result.at("world_features");
  std::map<std::string, json> holes;
  for (const auto& h : features.at("screw_holes")) holes[h.at("id")] = h;
  for (const char* id : {"m1", "m2", "m3", "m4"}) {
    ASSERT_EQ(holes.count(id), 1u) << id << " " << features.dump(2);
    EXPECT_EQ(holes[id].at("screw_type"), "M12x40");
  }
  // The same four holes as the target's own h1..h4, as the world model derives them.
  std::set<std::string> ours, declared;
  for (const auto& [id, h] : holes) (id[0] == 'h' ? ours : declared).insert((h.contains("pose") ? h.at("pose") : h).at("position_m").dump());
  EXPECT_EQ(declared, ours);
  bool grasp = false;
  for (const auto& g : features.at("grasp_frames")) grasp = grasp || g.at("id") == "grasp_declared";
  EXPECT_TRUE(grasp) << features.dump(2);
  const std::string audit_text = audit_log();
  EXPECT_NE(audit_text.find("declare screw_holes target/m"), std::string::npos) << audit_text;
  EXPECT_EQ(audit_text.find("declare screw_holes target/h"), std::string::npos) << "the taken name reached the world model";
  // The new model: the shipped h1 and the declared m1 (the same hole) are gone, the other holes stay.
  std::set<std::string> left;
  for (const auto& h : result.at("world_after_replace").value("screw_holes", json::array())) left.insert(h.at("id"));
  EXPECT_EQ(left, (std::set<std::string>{"h2", "h3", "h4", "m2", "m3", "m4"})) << result.dump(2);
  EXPECT_NE(audit_text.find("cell replace the model of target"), std::string::npos) << audit_text;
  std::printf("%s\nbrowser artifacts in %s\n", result.value("replaced", "").c_str(), cell_.log_dir().c_str());
}

}  // namespace
}  // namespace rigger::testing
