// A new product in the Planner (docs/console.md, "Your own product"): two STEP files the repository does not
// ship, written here with OpenCascade before any service starts (rigger::sim::write_new_product: an L bracket
// with two through holes, a base plate with six holes of two diameters on a pattern that is not a rectangle),
// become the paper's task in a real browser (planner/new_product.mjs) against the real CAD service, world
// model, task controller and console, with scripted executors announcing the real skill library on a private
// DDS domain. Through the page only: imported, added to the cell, the plate placed on the target by picks,
// the features declared by picks (each a confirmed cell revision), the paper's tree shape built by clicks,
// validated, exported and published; no coordinate typed (the page's count says which fields were typed).
// This test checks what the system made of it, against the geometry it wrote:
//  - the world model serves the plate where the picks put it (its bottom face on the target's top face) and
//    its six screw holes where the file has them, each with the screw type and torque of its pattern;
//  - the bracket's grasp, approach (100 mm out), rope attachment (at its hole), marker and its insertion
//    (its bottom face on the plate's top face, a hole of each lined up by the pin) are served as the picks
//    made them; the two markers' ids are the lowest no object carried (the page proposed them);
//  - the session met the goal for the paper's task on a new product: at most 120 clicks and 10 typed values;
//  - the exported recipe is canonical, names the planned objects and features, screws the six holes with the
//    world model's per-hole torques, and the published task ran to SUCCEEDED on the console's cell;
//  - the script itself checked that the session, replayed in a new page on the cell rolled back to where it
//    started, exported the same recipe and made the same cell document, byte for byte.
//  - Rehearse, clicked on the new product's plan, made the console start its rehearsal cell on a second
//    domain (world model, controller and scripted executors: write_scripted_rehearsal_cell) on the new
//    product's revision: that world model ran the revision's document (its sha256) before the controller
//    gave the rehearsed task a status, and the page showed it SUCCEEDED.
// The console's own cell and the rehearsal cell are scripted (as in the planner's other tests): a physics
// rehearsal of the new load is not part of this test (docs/decisions/0031).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "planner_test_support.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "rigger/testing/require.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

Eigen::Vector3d vec(const json& a) {
  return {a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()};
}

/// The pose of a world-model entity answer (world_pose, else pose; a quaternion, rotation rows or rpy_deg).
Eigen::Isometry3d pose_of(const json& entity) {
  const json& p = entity.contains("world_pose") ? entity.at("world_pose") : entity.at("pose");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = vec(p.at("position_m"));
  if (p.contains("quaternion_xyzw")) {
    const json& q = p.at("quaternion_xyzw");
    t.linear() = Eigen::Quaterniond(q.at(3).get<double>(), q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>())
                     .normalized()
                     .toRotationMatrix();
  } else if (p.contains("rotation")) {
    for (int i = 0; i < 3; ++i) t.linear().row(i) = vec(p.at("rotation").at(i)).transpose();
  } else {
    const Eigen::Vector3d rpy = vec(p.at("rpy_deg")) * M_PI / 180.0;
    t.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return t;
}

class PlannerNewProductTest : public WithRehearsalCell<PlannerCellTest> {
 protected:
  std::map<std::string, int> task_states_;
  std::unique_ptr<dds::Reader<rigger_task_TaskStatus>> status_;
};

TEST_F(PlannerNewProductTest, ANewProductImportedPlacedDeclaredAndProgrammedByClicksOnly) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  // Every file this test writes is written here, before the cell starts.
  const sim::NewProductModels models = sim::write_new_product(cell_.log_dir() + "/new-product");
  status_ = std::make_unique<dds::Reader<rigger_task_TaskStatus>>(cell_.participant(), protocol::task::kStatus);
  cell_.loop().on_data(*status_, [this] {
    status_->take([this](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      task_states_[dds::to_string(s.task_id)] = s.state;
    });
  });
  // The rehearsal cell the console starts on demand, on the revision it rehearses: scripted executors.
  const std::string script = write_scripted_rehearsal_cell(rehearsal_.log_dir(), true);
  std::vector<std::string> seen;  // on the rehearsal domain, in order: its world model's revisions, task statuses
  dds::Reader<rigger_world_CellRevision> revisions(rehearsal_.participant(), protocol::world::kCell);
  dds::Reader<rigger_task_TaskStatus> statuses(rehearsal_.participant(), protocol::task::kStatus);
  rehearsal_.loop().on_data(revisions, [&] {
    revisions.take([&](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
      seen.push_back("revision " + world_protocol::from_wire(w).sha256);
    });
  });
  rehearsal_.loop().on_data(statuses, [&] {
    statuses.take(
        [&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) { seen.push_back("task " + dds::to_string(s.task_id)); });
  });
  ASSERT_TRUE(start_planner_services(
      {{"rehearsal_domain", rehearsal_.domain_id()},
       {"rehearsal",
        {{"start", {"/bin/sh", script}}, {"log_file", rehearsal_.log_dir() + "/rehearsal-cell.log"}, {"idle_stop_s", 3},
         {"start_timeout_s", 40}, {"stop_timeout_s", 10}}}}));
  const std::string result_file = cell_.log_dir() + "/new-product-result.json";
  ASSERT_TRUE(run_browser_script("test/integration/planner/new_product.mjs", result_file, std::chrono::minutes(6),
                                 {{"BRACKET", models.bracket.string()}, {"PLATE", models.plate.string()}}, &rehearsal_));
  std::ifstream in(result_file);
  const json result = json::parse(in);
  const json& world = result.at("world");

  // The plate: its bottom face (z = -0.03 m in its frame) on the target's top face (z = 0 in the target's).
  const Eigen::Isometry3d plate = pose_of(world.at("base_plate"));
  const Eigen::Isometry3d target = pose_of(world.at("target"));
  const Eigen::Vector3d bottom_in_target = target.inverse() * (plate * Eigen::Vector3d(0, 0, -0.03));
  EXPECT_NEAR(bottom_in_target.z(), 0.0, 1e-6) << "the plate's bottom face is not on the target's top face";
  EXPECT_NEAR((plate.linear() * Eigen::Vector3d::UnitZ()).dot(target.linear() * Eigen::Vector3d::UnitZ()), 1.0, 1e-9);

  // Its six holes where the file has them, torque and screw type by pattern: 17.5 mm ones 120 N·m, 14 mm 80.
  const std::map<std::pair<int, int>, std::pair<std::string, double>> expected = {
      {{-150, -120}, {"M20x60", 120}}, {{150, -120}, {"M20x60", 120}}, {{110, 120}, {"M20x60", 120}},
      {{-110, 120}, {"M20x60", 120}},  {{-50, 0}, {"M16x50", 80}},     {{90, 40}, {"M16x50", 80}}};
  const json& holes = world.at("base_plate").at("features").at("screw_holes");
  ASSERT_EQ(holes.size(), 6u) << holes.dump(2);
  std::map<std::string, double> torque_of;
  std::set<std::pair<int, int>> holes_at;
  for (const json& h : holes) {
    const Eigen::Vector3d p = vec(h.at("pose").at("position_m"));
    const std::pair<int, int> mm{static_cast<int>(std::lround(p.x() * 1e3)), static_cast<int>(std::lround(p.y() * 1e3))};
    ASSERT_EQ(expected.count(mm), 1u) << "a hole at " << p.transpose() << " the file does not have: " << h.dump();
    EXPECT_NEAR(p.z(), 0.0, 1e-6) << h.dump();
    EXPECT_EQ(h.at("screw_type"), expected.at(mm).first) << h.dump();
    EXPECT_EQ(h.at("torque_nm").get<double>(), expected.at(mm).second) << h.dump();
    torque_of["base_plate/" + h.at("id").get<std::string>()] = h.at("torque_nm").get<double>();
    holes_at.insert(mm);
  }
  EXPECT_EQ(holes_at.size(), 6u) << "two holes declared at one place";

  // The bracket's features as the picks made them.
  const json& bracket = world.at("bracket").at("features");
  const auto frame_of = [&](const char* list, const char* id) -> json {
    for (const json& f : bracket.at(list))
      if (f.at("id") == id) return f.contains("pose") ? f.at("pose") : f;
    ADD_FAILURE() << "bracket has no " << list << " " << id << ": " << bracket.dump(2);
    return json::object();
  };
  const json grasp = frame_of("grasp_frames", "grasp");
  const json approach = frame_of("approach_waypoints", "pre_grasp");
  ASSERT_TRUE(grasp.contains("position_m") && approach.contains("position_m")) << bracket.dump(2);
  EXPECT_NEAR(vec(grasp.at("position_m")).x(), -0.17, 1e-6) << "the grasp is not on the web's inner face";
  EXPECT_NEAR((vec(approach.at("position_m")) - vec(grasp.at("position_m"))).norm(), 0.10, 1e-6)
      << "the approach is not 100 mm out of the grasp";
  const Eigen::Vector3d rope = vec(bracket.at("rope_attachment").at("position_m"));
  EXPECT_NEAR(rope.x(), 0.06, 1e-6);
  EXPECT_NEAR(std::abs(rope.y()), 0.09, 1e-6) << "the rope is not at a hole of the bracket";
  ASSERT_EQ(bracket.at("markers").at("items").size(), 1u) << bracket.dump(2);
  // Their ids as the page proposed them: the lowest that no object of the cell carries, the plate's first.
  std::set<int> used;
  const json shipped = json::parse(std::ifstream(repo_file("deploy/cell/simulated_cell.json")));
  for (const json& e : shipped.at("entities"))
    if (e.contains("features") && e.at("features").contains("markers"))
      for (const json& m : e.at("features").at("markers").at("items")) used.insert(m.at("id").get<int>());
  std::vector<int> free_ids;
  for (int id = 0; free_ids.size() < 2; ++id)
    if (used.count(id) == 0) free_ids.push_back(id);
  EXPECT_EQ(world.at("base_plate").at("features").at("markers").at("items").at(0).at("id"), free_ids[0]);
  EXPECT_EQ(bracket.at("markers").at("items").at(0).at("id"), free_ids[1]);
  const json& insertion = bracket.at("insertion");
  EXPECT_EQ(insertion.at("target"), "base_plate");
  // The bracket's bottom face (z = 0) on the plate's top face (z = 0), pinned: its hole at (0.06, 0.09) on the
  // plate's at (0.09, 0.04).
  const Eigen::Isometry3d inserted = pose_of(json{{"pose", insertion.at("pose_in_target")}});
  EXPECT_NEAR(insertion.at("pose_in_target").at("position_m").at(2).get<double>(), 0.0, 1e-6) << insertion.dump(2);
  EXPECT_LT((inserted * Eigen::Vector3d(0.06, 0.09, 0.0) - Eigen::Vector3d(0.09, 0.04, 0.0)).norm(), 1e-6)
      << "the pin does not line the holes up: " << insertion.dump(2);

  // The export: canonical, the planned objects and features, the six holes with the world model's torques.
  const std::string exported = result.at("exported");
  const json recipe = json::parse(exported);
  EXPECT_EQ(exported, recipe.dump(2) + "\n") << "the export is not in canonical form";
  const json& root = recipe.at("root");
  ASSERT_EQ(root.at("children").size(), 6u) << root.dump(2);
  const json attach = root.at(json::json_pointer("/children/2/children/0"));
  EXPECT_EQ(attach.at("params").at("grasp"), "bracket/grasp");
  EXPECT_EQ(attach.at("params").at("approach"), "bracket/pre_grasp");
  const json& screw = root.at("children").at(4);
  ASSERT_EQ(screw.at("skill"), "Screw");
  std::set<std::string> screwed;
  for (const json& h : screw.at("params").at("holes")) screwed.insert(h.get<std::string>());
  EXPECT_EQ(screwed.size(), 6u) << screw.dump(2);
  for (const json& s : screw.at("bindings").at("holes").at("screws")) {
    const std::string feature = s.at("feature");
    ASSERT_EQ(torque_of.count(feature), 1u) << s.dump();
    if (s.contains("torque_nm")) {
      EXPECT_EQ(s.at("torque_nm").get<double>(), torque_of.at(feature)) << s.dump();
    }
  }

  // Rehearsed on the new product's revision: the rehearsal cell's world model ran that document (sha256)
  // before its controller gave the rehearsed task a status.
  std::string order;
  for (const auto& line : seen) order += line + "\n";
  const auto revision_at = std::find(seen.begin(), seen.end(), "revision " + result.at("replay").at("cell").at("sha256").get<std::string>());
  const auto task_at = std::find(seen.begin(), seen.end(), "task " + result.at("rehearsal").at("task_id").get<std::string>());
  ASSERT_NE(revision_at, seen.end()) << "the rehearsal cell never ran the new product's revision\n" << order;
  ASSERT_NE(task_at, seen.end()) << order;
  EXPECT_LT(revision_at, task_at) << order;
  EXPECT_EQ(result.at("rehearsal").at("state"), "SUCCEEDED");

  // Published: the console's cell (scripted executors) ran it to its end.
  const std::string task = result.at("published");
  const auto ended = [&] {
    const auto it = task_states_.find(task);
    return it != task_states_.end() && (it->second == rigger_task_TASK_SUCCEEDED || it->second == rigger_task_TASK_FAILED ||
                                        it->second == rigger_task_TASK_CANCELED || it->second == rigger_task_TASK_REJECTED);
  };
  ASSERT_TRUE(cell_.wait_until(ended, 60s)) << "the published task " << task << " did not end";
  EXPECT_EQ(task_states_.at(task), rigger_task_TASK_SUCCEEDED) << protocol::task::task_state_name(task_states_.at(task));

  const json& effort = result.at("effort").at("counts");
  std::printf(
      "new product programmed in the browser: %d clicks, %d choices from lists, %d fields typed (%d characters), "
      "%.1f s of session (goal: 120 clicks, 10 typed values); cell revisions %d -> %d; timings (ms) %s; "
      "artifacts in %s\n",
      effort.at("clicks").get<int>(), effort.at("choices").get<int>(), effort.at("fields_typed").get<int>(),
      effort.at("characters").get<int>(), result.at("timings_ms").at("session").get<double>() / 1e3,
      result.at("revision_before").get<int>(), result.at("revision_declared").get<int>(),
      result.at("timings_ms").dump().c_str(), cell_.log_dir().c_str());
  // The goal for the paper's task on a new product: counted actions, the same in every run.
  EXPECT_LE(effort.at("clicks").get<int>(), 120);
  EXPECT_LE(effort.at("fields_typed").get<int>(), 10);
}

}  // namespace
}  // namespace rigger::testing
